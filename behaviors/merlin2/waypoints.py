"""SAILOR's map as MERLIN2's waypoint navigation knows waypoints: one map for both.

MERLIN2's ``waypoint_navigation`` node (``waypoint_navigation_msgs/NavigateToWp``) reads its
waypoints from a parameter ``wps``: a flat list of strings, five per waypoint (name, x, y, and the
orientation's quaternion z and w, a heading about the vertical axis). SAILOR's grounding map
names the same places; :func:`waypoint_navigation_parameters` writes them in that shape, so both
drive to the same pose under the same name. A waypoint without a heading gets heading 0.

``python -m merlin2_sailor_behaviors.merlin2.waypoints [GROUNDING]`` prints a parameter file for
the node (``ros2 run waypoint_navigation waypoint_navigation_node --ros-args --params-file ...``);
with ``--serve`` it runs MERLIN2's node itself, unmodified, in /waypoint_navigation, with those
waypoints (Ctrl-C stops it).
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence

import yaml
from rclpy.utilities import remove_ros_args

from merlin2_sailor.errors import SailorError
from merlin2_sailor.knowledge.grounding import GroundingConfig
from merlin2_sailor.resources import config_path
from merlin2_sailor_behaviors.actions.places import Places

NODE_NAME = "waypoint_navigation_node"
NAMESPACE = "waypoint_navigation"


def waypoint_navigation_parameters(places: Places) -> list[str]:
    """The ``wps`` parameter of MERLIN2's waypoint_navigation node for every waypoint of the map."""
    values: list[str] = []
    for name in places.waypoint_names():
        place = places.get(name)
        yaw = place.yaw or 0.0
        values += [name, repr(place.x), repr(place.y), repr(math.sin(yaw / 2)), repr(math.cos(yaw / 2))]
    return values


def parameter_file(places: Places) -> str:
    """A ROS 2 parameter file with the waypoints, for the node under its launch's namespace."""
    document = {NAMESPACE: {NODE_NAME: {"ros__parameters": {"wps": waypoint_navigation_parameters(places)}}}}
    return yaml.safe_dump(document, sort_keys=False)


def serve(places: Places, arguments: Sequence[str]) -> int:
    """Run MERLIN2's waypoint_navigation node with the map's waypoints until Ctrl-C."""
    try:
        from waypoint_navigation.waypoint_navigation_node import WaypointNavigationNode
    except ImportError as error:
        print(f"cannot start: MERLIN2's waypoint_navigation is not importable ({error}); build it in the "
              "workspace and source it", file=sys.stderr)
        return 2
    import rclpy

    from merlin2_sailor_behaviors.merlin2.node_threads import let_node_threads_end, ros_shutdown_ends_node_threads

    waypoints = yaml.safe_dump(waypoint_navigation_parameters(places), default_flow_style=True).strip()
    # The waypoints first: what the command line says (--ros-args ...) comes after and wins.
    rclpy.init(args=[arguments[0], "--ros-args", "-r", f"__ns:=/{NAMESPACE}", "-p", f"wps:={waypoints}",
                     "--", *arguments[1:]])
    node = WaypointNavigationNode()
    print(f"serving NavigateToWp at /{NAMESPACE}/navigate_to_wp for {', '.join(places.waypoint_names())}",
          flush=True)
    try:
        node.join_spin()
    except KeyboardInterrupt:
        pass
    finally:
        with ros_shutdown_ends_node_threads():
            node.destroy_node()
            rclpy.try_shutdown()
            let_node_threads_end([node])
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("grounding", nargs="?", default="",
                        help="grounding YAML, a path or one of config/ (default: config/grounding.yaml)")
    parser.add_argument("--serve", action="store_true",
                        help="run MERLIN2's waypoint_navigation node with these waypoints instead of printing them")
    arguments = [sys.argv[0], *(sys.argv[1:] if argv is None else argv)]
    options = parser.parse_args(remove_ros_args(arguments)[1:])  # --ros-args ... are ROS's
    try:
        places = Places.from_grounding(GroundingConfig.from_yaml(config_path(options.grounding, "grounding.yaml")))
    except (SailorError, OSError) as error:
        print(f"cannot read the map: {error}", file=sys.stderr)
        return 2
    if options.serve:
        return serve(places, arguments)
    sys.stdout.write(parameter_file(places))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
