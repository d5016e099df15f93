"""ros2 launch merlin2_sailor merlin2_house.launch.py: the same graph as launch/merlin2_house.yaml.

The house mission inside MERLIN2, in a workspace that has MERLIN2, KANT, YASMIN and
waypoint_navigation built: SAILOR's perception, anchoring (into KANT) and actions, MERLIN2's
knowledge base, planning layer and waypoint navigation, and a mission that explores every room.
"""

import os
import sys

from ament_index_python.packages import get_package_share_directory
from launch.actions import ExecuteProcess, Shutdown
from launch_ros.actions import Node

from launch import LaunchDescription

GROUNDING = "worlds/house_grounding.yaml"
GOALS = ["explored(kitchen)", "explored(living_room)", "explored(hall)", "explored(bedroom)"]


def generate_launch_description() -> LaunchDescription:
    config = os.path.join(get_package_share_directory("merlin2_sailor"), "config")
    data = os.environ.get("SAILOR_DATA", os.path.join(os.path.expanduser("~"), ".sailor", "merlin2"))

    def parameters(name: str, **overrides: object) -> list:
        return [os.path.join(config, f"{name}.yaml")] + ([overrides] if overrides else [])

    def python_module(module: str, *arguments: str, **options: object) -> ExecuteProcess:
        return ExecuteProcess(cmd=[sys.executable, "-m", module, *arguments], output="screen", **options)

    return LaunchDescription([
        Node(package="kant_knowledge_base", executable="knowledge_base_node.py", namespace="merlin2",
             output="screen"),
        Node(package="merlin2_sailor", executable="world", output="screen",
             parameters=parameters("world", world_file="worlds/house.yaml", report_folder=data, log_period=0.0)),
        Node(package="merlin2_sailor", executable="percept_generator", namespace="camera", output="screen",
             parameters=parameters("percept_generator", maximum_depth=4.5, report_period=60.0)),
        Node(package="merlin2_sailor", executable="anchoring", output="screen",
             parameters=parameters("anchoring", state_folder=f"{data}/anchoring", knowledge_base="kant+ros:///merlin2",
                                   grounding=GROUNDING, rules_maximum_sigma=0.3, visible_range=4.5),
             remappings=[("percepts", "/camera/percepts"),
                         ("color/camera_info", "/camera/color/camera_info"),
                         ("camera_pose", "/camera/camera_pose"),
                         ("depth/image_raw", "/camera/depth/image_raw")]),
        python_module("merlin2_sailor_behaviors.merlin2.waypoints", GROUNDING, "--serve"),
        python_module("merlin2_sailor_behaviors.merlin2.run", "navigation", "explore", "--grounding", GROUNDING,
                      "--look-dwell", "0.3"),
        Node(package="merlin2_pddl_generator", executable="pddl_generator_node", output="screen"),
        python_module("merlin2_sailor_behaviors.merlin2.planner", "--ros-args", "-p", "planner:=3"),
        Node(package="merlin2_plan_dispatcher", executable="plan_dispatcher_node", output="screen"),
        Node(package="merlin2_executor", executable="executor_node", output="screen"),
        python_module("merlin2_sailor_behaviors.merlin2.mission", *GOALS, "--grounding", GROUNDING,
                      on_exit=Shutdown()),
    ])
