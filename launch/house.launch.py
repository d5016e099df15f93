"""ros2 launch merlin2_sailor house.launch.py: the same graph as launch/house.yaml."""

import os

from ament_index_python.packages import get_package_share_directory
from launch_ros.actions import Node

from launch import LaunchDescription


def generate_launch_description() -> LaunchDescription:
    config = os.path.join(get_package_share_directory("merlin2_sailor"), "config")
    data = os.environ.get("SAILOR_DATA", os.path.join(os.path.expanduser("~"), ".sailor", "house"))
    grounding = os.path.join(config, "worlds", "house_grounding.yaml")

    def parameters(name: str, **overrides: object) -> list:
        return [os.path.join(config, f"{name}.yaml")] + ([overrides] if overrides else [])

    return LaunchDescription([
        Node(package="merlin2_sailor", executable="world",
             parameters=parameters("world", world_file=os.path.join(config, "worlds", "house.yaml"),
                                   report_folder=data),
             output="screen"),
        Node(package="merlin2_sailor", executable="percept_generator", namespace="camera",
             parameters=parameters("percept_generator", maximum_depth=4.5), output="screen"),
        Node(package="merlin2_sailor", executable="knowledge_base", namespace="merlin2",
             parameters=parameters("knowledge_base", store=f"sqlite://{data}/knowledge.db"), output="screen"),
        Node(package="merlin2_sailor", executable="anchoring",
             parameters=parameters("anchoring", state_folder=f"{data}/anchoring",
                                   knowledge_base="ros:///merlin2", grounding=grounding,
                                   rules_maximum_sigma=0.3, visible_range=4.5),
             remappings=[("percepts", "/camera/percepts"),
                         ("color/camera_info", "/camera/color/camera_info"),
                         ("camera_pose", "/camera/camera_pose"),
                         ("depth/image_raw", "/camera/depth/image_raw")],
             output="screen"),
        Node(package="merlin2_sailor", executable="behaviors",
             parameters=parameters("behaviors", grounding=grounding, look_dwell=0.3), output="screen"),
    ])
