"""ros2 launch merlin2_sailor knowledge.launch.py: the same graph as launch/knowledge.yaml."""

import os

from ament_index_python.packages import get_package_share_directory
from launch_ros.actions import Node

from launch import LaunchDescription


def generate_launch_description() -> LaunchDescription:
    config = os.path.join(get_package_share_directory("merlin2_sailor"), "config")
    database = os.path.join(os.path.expanduser("~"), ".sailor", "knowledge.db")
    return LaunchDescription([
        Node(
            package="merlin2_sailor",
            executable="knowledge_base",
            namespace="merlin2",
            parameters=[os.path.join(config, "knowledge_base.yaml"), {"store": f"sqlite://{database}"}],
            output="screen",
        ),
    ])
