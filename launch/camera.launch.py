"""ros2 launch merlin2_sailor camera.launch.py: the same graph as launch/camera.yaml.

For users with a full ROS 2 Jazzy installation (ros2launch and launch_ros are not on PyPI; the
venv set-up uses ``sailor launch camera`` instead).
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
            executable="topic_monitor",
            parameters=[
                os.path.join(config, "topic_monitor.yaml"),
                {"topics": [
                    "/camera/color/image_raw",
                    "/camera/depth/image_raw",
                    "/camera/color/camera_info",
                    "/camera/camera_pose",
                ]},
            ],
            output="screen",
        ),
    ])
