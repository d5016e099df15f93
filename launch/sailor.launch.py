"""ros2 launch merlin2_sailor sailor.launch.py: the same graph as launch/sailor.yaml."""

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
        Node(package="merlin2_sailor", executable="knowledge_base", namespace="merlin2",
             parameters=parameters("knowledge_base", store=f"sqlite://{data}/knowledge.db"), output="screen"),
        Node(package="merlin2_sailor", executable="anchoring",
             parameters=parameters("anchoring", state_folder=f"{data}/anchoring",
                                   knowledge_base="ros:///merlin2"),
             remappings=[("percepts", "/camera/percepts"),
                         ("color/camera_info", "/camera/color/camera_info"),
                         ("camera_pose", "/camera/camera_pose"),
                         ("depth/image_raw", "/camera/depth/image_raw")],
             output="screen"),
        Node(package="merlin2_sailor", executable="topic_monitor",
             parameters=parameters("topic_monitor", report_period=5.0,
                                   topics=["/camera/color/image_raw", "/camera/detections",
                                           "/camera/percepts", "/anchors"]),
             output="screen"),
    ])
