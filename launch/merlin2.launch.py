"""ros2 launch merlin2_sailor merlin2.launch.py: the same graph as launch/merlin2.yaml.

SAILOR's perception and anchoring inside a MERLIN2 deployment: anchors go into KANT, MERLIN2's
knowledge base, in /merlin2; SAILOR's own knowledge_base node is not started.
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch_ros.actions import Node

from launch import LaunchDescription


def generate_launch_description() -> LaunchDescription:
    config = os.path.join(get_package_share_directory("merlin2_sailor"), "config")
    data = os.environ.get("SAILOR_DATA", os.path.join(os.path.expanduser("~"), ".sailor"))

    def parameters(name: str, **overrides: object) -> list:
        return [os.path.join(config, f"{name}.yaml")] + ([overrides] if overrides else [])

    return LaunchDescription([
        Node(package="merlin2_sailor", executable="rgbd_player", namespace="camera",
             parameters=parameters("rgbd_player"), output="screen"),
        Node(package="merlin2_sailor", executable="detector", namespace="camera",
             parameters=parameters("detector"), output="screen"),
        Node(package="merlin2_sailor", executable="percept_generator", namespace="camera",
             parameters=parameters("percept_generator"), output="screen"),
        Node(package="merlin2_sailor", executable="anchoring",
             parameters=parameters("anchoring", state_folder=f"{data}/anchoring",
                                   knowledge_base="kant+ros:///merlin2"),
             remappings=[("percepts", "/camera/percepts"),
                         ("color/camera_info", "/camera/color/camera_info"),
                         ("camera_pose", "/camera/camera_pose"),
                         ("depth/image_raw", "/camera/depth/image_raw")],
             output="screen"),
    ])
