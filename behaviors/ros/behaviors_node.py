"""behaviors: SAILOR's state-machine behaviours served as RunPddlAction action servers.

For each action it serves (``actions``; all by default) the node offers an action server
``~/<action_name>`` (``/behaviors/navigation`` under the default name), registers the PDDL
action (with the types and predicates it needs) in the knowledge base once it is reachable, and
withdraws it when the node stops. When it serves ``navigation`` and the knowledge base holds no
``robot_at`` fact, it declares ``robot_at(<waypoint nearest the robot>)`` from the first robot
pose, so a mission can plan from the start.

Behaviours reach the robot through the anchoring node's services (``<anchoring>/get_anchors``,
``find_anchor``, ``expect_anchor``), a NavigateToPose action server, a ``robot_pose`` topic and a
Grasp service; the map is the grounding configuration the anchoring layer uses, and its places
are declared as ``wp`` objects with the actions. Every parameter is documented in
config/behaviors.yaml.

Threads: one executor serves goals, cancels, service and action responses, poses and the feedback
timer, and never waits: each goal's state machine runs on a worker thread of its own, making
blocking calls whose answers the executor delivers. Registration runs on a thread of its own,
retrying while the knowledge base is away; the knowledge base is reached through its own client
context.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from typing import Any

from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node

from merlin2_sailor.errors import ConfigurationError, KnowledgeError
from merlin2_sailor.knowledge import Change, KnowledgeBase, PddlObject
from merlin2_sailor.knowledge.grounding import GroundingConfig
from merlin2_sailor.resources import config_path
from merlin2_sailor.ros.node_runner import run_node
from merlin2_sailor.ros.parameters import declare_parameter
from merlin2_sailor.ros.stores import open_store
from merlin2_sailor_behaviors.actions.context import BehaviorConfig, BehaviorContext
from merlin2_sailor_behaviors.actions.domain import LOCATION_TYPE
from merlin2_sailor_behaviors.actions.errors import BehaviorError
from merlin2_sailor_behaviors.actions.places import Places
from merlin2_sailor_behaviors.actions.robot_location import declare_robot_at, robot_locations
from merlin2_sailor_behaviors.actions.sailor_action import SailorAction
from merlin2_sailor_behaviors.catalogue import SAILOR_ACTIONS, select_actions
from merlin2_sailor_behaviors.ros.anchoring_client import RosAnchoringClient
from merlin2_sailor_behaviors.ros.fsm_viewer import VIEWER_PERIOD, FsmViewerPublisher
from merlin2_sailor_behaviors.ros.grasp_client import RosGraspClient
from merlin2_sailor_behaviors.ros.navigation_client import RosNavigationClient
from merlin2_sailor_behaviors.ros.pddl_action_server import Body, PddlActionServer
from merlin2_sailor_behaviors.ros.service_caller import ServiceCaller

NODE_NAME = "behaviors"
SHUTDOWN_WAIT_SECONDS = 5.0
FEEDBACK_PERIOD = 0.05
"""Seconds between two looks at which state each running machine is in."""


class BehaviorsNode(Node):
    def __init__(self, **node_options: Any) -> None:
        super().__init__(NODE_NAME, **node_options)
        names = declare_parameter(
            self, "actions", list(SAILOR_ACTIONS),
            f"Actions to serve, each as the action server ~/<name>; of {list(SAILOR_ACTIONS)}.")
        location = declare_parameter(
            self, "knowledge_base", "ros:///merlin2",
            "Knowledge base the actions are registered in: ros:///namespace, sqlite:///path, "
            "mongodb://host/db or memory.")
        knowledge_timeout = declare_parameter(
            self, "knowledge_base_timeout", 2.0, "Seconds to wait for a knowledge-base service.",
            minimum=0.1, maximum=60.0)
        retry_period = declare_parameter(
            self, "registration_retry_period", 2.0,
            "Seconds between attempts to register the actions while the knowledge base is away.",
            minimum=0.1, maximum=60.0)
        grounding = declare_parameter(
            self, "grounding", "", "Grounding YAML whose map gives the waypoints; empty: config/grounding.yaml.")
        anchoring = declare_parameter(
            self, "anchoring", "/anchoring", "Fully qualified name of the anchoring node whose services are used.")
        navigation_action = declare_parameter(
            self, "navigation_action", "navigate_to_pose", "NavigateToPose action server to drive with.")
        waypoint_action = declare_parameter(
            self, "waypoint_navigation_action", "",
            "NavigateToWp action server (MERLIN2's waypoint navigation) to drive to the map's waypoints by name; "
            "empty: drive to them with NavigateToPose.")
        robot_pose_topic = declare_parameter(
            self, "robot_pose_topic", "robot_pose", "PoseStamped topic with the robot's pose on the map.")
        frame_id = declare_parameter(self, "frame_id", "map", "Frame of navigation goals (the map).")
        grasp_service = declare_parameter(
            self, "grasp_service", "/world/grasp", "Grasp service to pick and place with.")
        service_timeout = declare_parameter(
            self, "service_timeout", 2.0,
            "Seconds to wait for an anchoring or grasp service to appear and answer.", minimum=0.1, maximum=60.0)
        server_timeout = declare_parameter(
            self, "navigation_server_timeout", 5.0,
            "Seconds to wait for the NavigateToPose server to appear and accept a goal.", minimum=0.1, maximum=120.0)
        goal_timeout = declare_parameter(
            self, "navigation_goal_timeout", 300.0,
            "Seconds a navigation goal may take before it is cancelled as failed.", minimum=1.0, maximum=3600.0)
        self._declare_robot_at = declare_parameter(
            self, "declare_robot_at", True,
            "Declare robot_at(<nearest waypoint>) at start when the knowledge base has no robot_at fact.")
        config = self._behavior_config()

        grounding_config = GroundingConfig.from_yaml(config_path(grounding, "grounding.yaml"))
        if grounding_config.location_type != LOCATION_TYPE:
            raise ConfigurationError(
                f"the behaviours' domain uses waypoints of type {LOCATION_TYPE!r}, but the grounding's "
                f"location_type is {grounding_config.location_type!r}; make them the same")
        try:
            places = Places.from_grounding(grounding_config)
        except BehaviorError as error:
            raise ConfigurationError(str(error)) from error
        self._actions: tuple[SailorAction, ...] = select_actions(names)
        self._stopping = threading.Event()
        self._store = self._open_store(location, knowledge_timeout)
        self._registered: list[SailorAction] = []
        self._places = places

        group = ReentrantCallbackGroup()
        caller = ServiceCaller(self, service_timeout, self._stopping, group)
        self._navigation = RosNavigationClient(
            self, self._stopping, navigation_action, robot_pose_topic, frame_id, server_timeout, goal_timeout, group,
            waypoint_action)
        context = BehaviorContext(
            store=self._store,
            anchoring=RosAnchoringClient(caller, anchoring),
            navigation=self._navigation,
            grasp=RosGraspClient(caller, grasp_service),
            places=places,
            config=config,
            log=self._log,
        )
        body = Body()
        self._servers = [
            PddlActionServer(self, action, context, f"~/{action.name}", body, self._stopping, self._log, group)
            for action in self._actions
        ]
        self.create_timer(FEEDBACK_PERIOD, self._publish_progress, callback_group=group)
        self._viewer = FsmViewerPublisher(self)
        if self._viewer.enabled:
            self.create_timer(VIEWER_PERIOD, self._publish_to_viewer, callback_group=group)
        self._registration = threading.Thread(
            target=self._register, args=(retry_period,), name="behaviors-registration", daemon=True)
        self._registration.start()
        self.get_logger().info(
            f"serving {[action.name for action in self._actions]} as {self.get_fully_qualified_name()}/<action>; "
            f"knowledge base: {location}; map: {len(places.waypoint_names())} waypoints")

    # Construction helpers.

    def _behavior_config(self) -> BehaviorConfig:
        defaults = BehaviorConfig()
        values = {
            "look_around_turns": declare_parameter(
                self, "look_around_turns", defaults.look_around_turns,
                "Goals to turn in place through 360 degrees when looking around (0: only dwell).",
                minimum=0, maximum=36),
            "look_dwell": declare_parameter(
                self, "look_dwell", defaults.look_dwell, "Seconds to stand still after each turn.",
                minimum=0.0, maximum=60.0),
            "look_fresh_for": declare_parameter(
                self, "look_fresh_for", defaults.look_fresh_for,
                "explore: seconds a look-around on arrival at the same waypoint counts (0: always look).",
                minimum=0.0, maximum=3600.0),
            "approach_timeout": declare_parameter(
                self, "approach_timeout", defaults.approach_timeout,
                "approach_object: seconds to wait for the object to be seen again.", minimum=0.0, maximum=600.0),
            "reacquire_timeout": declare_parameter(
                self, "reacquire_timeout", defaults.reacquire_timeout,
                "find_object: seconds to wait at each stop for a reacquisition.", minimum=0.0, maximum=600.0),
            "search_radius": declare_parameter(
                self, "search_radius", defaults.search_radius,
                "find_object: metres around a search stop where a percept of the class may be the sought object.",
                minimum=0.0, maximum=20.0),
            "confirm_timeout": declare_parameter(
                self, "confirm_timeout", defaults.confirm_timeout,
                "bring: seconds to look at the placed object for perception to confirm it.",
                minimum=0.0, maximum=600.0),
            "poll_period": declare_parameter(
                self, "poll_period", defaults.poll_period,
                "Seconds between questions to the anchoring layer while waiting.", minimum=0.01, maximum=10.0),
            "carry_offset": tuple(declare_parameter(
                self, "carry_offset", list(defaults.carry_offset),
                "bring: where a carried object is in the robot's base frame (x, y, z metres).")),
            "place_distance": declare_parameter(
                self, "place_distance", defaults.place_distance,
                "bring: metres in front of the robot the object is put down.", minimum=0.0, maximum=5.0),
            "return_on_failure": declare_parameter(
                self, "return_on_failure", defaults.return_on_failure,
                "find_object: drive back to the origin when the object was found nowhere."),
        }
        return BehaviorConfig(**values)

    def _open_store(self, location: str, timeout: float) -> KnowledgeBase:
        return open_store(location, timeout=timeout)

    def _publish_progress(self) -> None:
        for server in self._servers:
            server.publish_progress()

    def _publish_to_viewer(self) -> None:
        for server in self._servers:
            for machine in server.running_machines():
                self._viewer.publish(server.action.name, machine)

    def _log(self, level: str, message: str) -> None:
        # One call site per severity: rclpy refuses a call site whose severity changes.
        logger = self.get_logger()
        if level == "debug":
            logger.debug(message)
        elif level == "warning":
            logger.warning(message)
        elif level == "error":
            logger.error(message)
        else:
            logger.info(message)

    # Registration, on its own thread.

    def _register(self, retry_period: float) -> None:
        reported = False
        while not self._stopping.is_set():
            try:
                for action in self._actions:
                    if action not in self._registered:
                        action.register(self._store)
                        self._registered.append(action)
                break
            except KnowledgeError as error:
                if not reported:
                    self.get_logger().warning(f"cannot register the actions yet, retrying: {error}")
                    reported = True
            self._stopping.wait(retry_period)
        else:
            return
        self.get_logger().info(f"registered {[action.name for action in self._registered]} in the knowledge base")
        self._declare_places()
        if self._declare_robot_at and any(action.name == "navigation" for action in self._actions):
            self._declare_start(retry_period)

    def _declare_places(self) -> None:
        """The map's places as ``wp`` objects, as the anchoring layer's grounding declares them
        too, so a mission can plan to a place before anything was anchored there."""
        try:
            missing = [name for name in self._places.names() if self._store.objects.get(name) is None]
            if missing:
                self._store.apply([Change.save(PddlObject(name, LOCATION_TYPE)) for name in missing])
        except KnowledgeError as error:
            self.get_logger().warning(f"could not declare the map's places: {error}")

    def _declare_start(self, retry_period: float) -> None:
        """robot_at(<nearest waypoint>) from the first robot pose, if nobody has said where it is."""
        while not self._stopping.is_set():
            pose = self._navigation.robot_pose()
            if pose is not None:
                try:
                    if robot_locations(self._store):
                        return
                    place = self._places.nearest_waypoint(pose.x, pose.y)
                    if place is None:
                        self.get_logger().warning("the map has no waypoint: robot_at not declared")
                        return
                    declare_robot_at(self._store, place)
                    self.get_logger().info(f"declared robot_at({place}): the waypoint nearest the robot")
                    return
                except KnowledgeError as error:
                    self.get_logger().warning(f"cannot declare where the robot is yet: {error}",
                                              throttle_duration_sec=10.0)
            self._stopping.wait(min(retry_period, 0.2) if pose is None else retry_period)

    # Shutdown.

    def destroy_node(self) -> None:
        self._stopping.set()
        for server in self._servers:
            server.cancel_all()
        for server in self._servers:
            if not server.wait_idle(SHUTDOWN_WAIT_SECONDS):
                self.get_logger().warning(f"{server.action.name} was still running at shutdown")
        self._registration.join(timeout=SHUTDOWN_WAIT_SECONDS)
        withdrawn = []
        for index, action in enumerate(self._registered):
            try:
                if action.unregister(self._store):
                    withdrawn.append(action.name)
            except KnowledgeError as error:
                # One failure says the knowledge base is gone (or going); asking again for each
                # action would only spend the launcher's grace period on timeouts.
                left = [later.name for later in self._registered[index:]]
                self.get_logger().warning(f"could not withdraw {left} from the knowledge base: {error}")
                break
        if withdrawn:
            self.get_logger().info(f"withdrew {withdrawn} from the knowledge base")
        self._store.close()
        for server in self._servers:
            server.destroy()
        self._navigation.destroy()
        super().destroy_node()


def main(argv: Sequence[str] | None = None) -> int:
    return run_node(BehaviorsNode, argv)


if __name__ == "__main__":
    raise SystemExit(main())
