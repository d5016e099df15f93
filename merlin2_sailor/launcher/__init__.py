"""Start a graph of ROS 2 nodes as processes from a YAML description.

``ros2 launch`` cannot be installed from PyPI, so this package provides the part of it the
project needs: read a launch description (:mod:`.spec`), turn each node into a command line
(:mod:`.command`), run and supervise the processes (:mod:`.supervisor`). It is ROS-free: nodes
are ordinary executables that receive ``--ros-args``.
"""

from merlin2_sailor.launcher.spec import LaunchSpec, NodeSpec, load_launch_file
from merlin2_sailor.launcher.supervisor import LaunchResult, ProcessOutcome, Supervisor

__all__ = [
    "LaunchResult",
    "LaunchSpec",
    "NodeSpec",
    "ProcessOutcome",
    "Supervisor",
    "load_launch_file",
]
