"""ros2 launch merlin2_sailor perception.launch.py: the same graph as launch/perception.yaml.

For users with a full ROS 2 Jazzy installation (ros2launch and launch_ros are not on PyPI; the
venv set-up uses ``sailor launch perception`` instead).
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch_ros.actions import Node

from launch import LaunchDescription


def generate_launch_description() -> LaunchDescription:
    config = os.path.join(get_package_share_directory("merlin2_sailor"), "config")
    return LaunchDescription([
        Node(
            package="merlin2_sailor",
            executable="rgbd_player",
            namespace="camera",
            parameters=[os.path.join(config, "rgbd_player.yaml")],
            output="screen",
        ),
        Node(
            package="merlin2_sailor",
            executable="detector",
            namespace="camera",
            parameters=[os.path.join(config, "detector.yaml")],
            output="screen",
        ),
        Node(
            package="merlin2_sailor",
            executable="percept_generator",
            namespace="camera",
            parameters=[os.path.join(config, "percept_generator.yaml")],
            output="screen",
        ),
        Node(
            package="merlin2_sailor",
            executable="topic_monitor",
            parameters=[
                os.path.join(config, "topic_monitor.yaml"),
                {"topics": [
                    "/camera/color/image_raw",
                    "/camera/detections",
                    "/camera/percepts",
                ]},
            ],
            output="screen",
        ),
    ])
