"""The behaviours' context on a MERLIN2 action node: ROS clients on that node, KANT as the store.

MERLIN2's knowledge base is KANT, reached through the DAO factory every MERLIN2 action node owns
(``node.dao_factory``), so the behaviours read and write it through
:class:`~merlin2_sailor.knowledge.kant_store.KantStore`. The clients (anchoring services,
NavigateToPose, NavigateToWp, Grasp) are the same as the ``behaviors`` node's, created on the MERLIN2 node,
which MERLIN2 spins on a multi-threaded executor of its own.
"""

from __future__ import annotations

import threading
from typing import Any

from rclpy.callback_groups import ReentrantCallbackGroup

from merlin2_sailor.knowledge.grounding import GroundingConfig
from merlin2_sailor.knowledge.kant_store import KantStore
from merlin2_sailor.resources import config_path
from merlin2_sailor.ros.navigation_interface import WAYPOINT_NAVIGATION_ACTION, waypoint_navigation_type
from merlin2_sailor_behaviors.actions.context import BehaviorConfig, BehaviorContext
from merlin2_sailor_behaviors.actions.places import Places
from merlin2_sailor_behaviors.merlin2.fsm_action import ContextFactory
from merlin2_sailor_behaviors.ros.anchoring_client import RosAnchoringClient
from merlin2_sailor_behaviors.ros.grasp_client import RosGraspClient
from merlin2_sailor_behaviors.ros.navigation_client import RosNavigationClient
from merlin2_sailor_behaviors.ros.service_caller import ServiceCaller


def ros_context_factory(
    grounding_file: str = "",
    anchoring: str = "/anchoring",
    navigation_action: str = "/navigate_to_pose",
    robot_pose_topic: str = "/robot_pose",
    frame_id: str = "map",
    grasp_service: str = "/world/grasp",
    service_timeout: float = 2.0,
    config: BehaviorConfig | None = None,
    waypoint_action: str | None = None,
) -> ContextFactory:
    """A factory of contexts for MERLIN2 action nodes, with the ``behaviors`` node's defaults,
    absolute (MERLIN2's action nodes live in /merlin2; Nav2 and the robot's pose do not).

    Waypoints are driven to through MERLIN2's waypoint navigation (``waypoint_action``; by default
    :data:`~merlin2_sailor.ros.navigation_interface.WAYPOINT_NAVIGATION_ACTION` where
    waypoint_navigation_msgs is installed, as MERLIN2's own navigation action does); every other
    goal (facing an object, turning in place) through NavigateToPose.
    """
    if waypoint_action is None:
        waypoint_action = WAYPOINT_NAVIGATION_ACTION if waypoint_navigation_type() is not None else ""
    places = Places.from_grounding(GroundingConfig.from_yaml(config_path(grounding_file, "grounding.yaml")))

    def make_context(node: Any, stopping: threading.Event) -> BehaviorContext:
        group = ReentrantCallbackGroup()
        caller = ServiceCaller(node, service_timeout, stopping, group)
        return BehaviorContext(
            store=KantStore(node.dao_factory),
            anchoring=RosAnchoringClient(caller, anchoring),
            navigation=RosNavigationClient(node, stopping, navigation_action, robot_pose_topic, frame_id,
                                           callback_group=group, waypoint_action=waypoint_action),
            grasp=RosGraspClient(caller, grasp_service),
            places=places,
            config=config or BehaviorConfig(),
        )

    return make_context
