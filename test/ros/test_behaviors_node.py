"""The behaviors node as a real process, with a knowledge_base node and a stand-in robot.

The stand-in (in this test's own ROS context) serves NavigateToPose (arriving at once, except at
waypoint ``c``, where it drives until cancelled), publishes the robot pose, and answers the
anchoring node's services from a table of anchors, recording every expectation.
"""

from __future__ import annotations

import math
import threading
import time
import uuid
from pathlib import Path

import pytest

pytestmark = pytest.mark.ros

GROUNDING = """\
location_type: wp
map:
  waypoints:
    - {name: a, x: 0.0, y: 0.0}
    - {name: b, x: 2.0, y: 0.0}
    - {name: c, x: 5.0, y: 0.0}
"""
BLOCKING_X = 5.0  # goals to waypoint c drive until cancelled


class StandInRobot:
    """NavigateToPose, robot_pose and the anchoring services, on a multi-threaded executor."""

    def __init__(self, prefix: str) -> None:
        import rclpy
        from geometry_msgs.msg import PoseStamped
        from rclpy.action import ActionServer, CancelResponse
        from rclpy.callback_groups import ReentrantCallbackGroup
        from rclpy.executors import MultiThreadedExecutor

        from merlin2_sailor.ros.navigation_interface import navigate_to_pose_type
        from merlin2_sailor_interfaces import srv

        self.context = rclpy.Context()
        rclpy.init(context=self.context)
        self.node = rclpy.create_node(f"stand_in_robot_{uuid.uuid4().hex[:6]}", context=self.context)
        group = ReentrantCallbackGroup()
        self.goals: list[tuple[float, float, float]] = []
        self.cancelled = threading.Event()
        self.driving = threading.Event()
        self.expectations: list = []
        self.anchors: list = []
        self.pose = (0.1, 0.0)
        self._pose_type = PoseStamped
        self._navigation = ActionServer(
            self.node, navigate_to_pose_type(), f"{prefix}/navigate_to_pose", self._navigate,
            cancel_callback=lambda goal: CancelResponse.ACCEPT, callback_group=group)
        self._pose_publisher = self.node.create_publisher(PoseStamped, f"{prefix}/robot_pose", 10)
        self.node.create_timer(0.1, self._publish_pose, callback_group=group)
        self.node.create_service(srv.GetAnchors, f"{prefix}/anchoring/get_anchors", self._get_anchors,
                                 callback_group=group)
        self.node.create_service(srv.ExpectAnchor, f"{prefix}/anchoring/expect_anchor", self._expect,
                                 callback_group=group)
        self._executor = MultiThreadedExecutor(num_threads=4, context=self.context)
        self._executor.add_node(self.node)
        self._thread = threading.Thread(target=self._spin, daemon=True)
        self._thread.start()

    def _spin(self) -> None:
        from rclpy.executors import ExternalShutdownException

        try:
            self._executor.spin()
        except ExternalShutdownException:
            pass

    def _publish_pose(self) -> None:
        message = self._pose_type()
        message.header.frame_id = "map"
        message.pose.position.x, message.pose.position.y = self.pose
        message.pose.orientation.w = 1.0
        self._pose_publisher.publish(message)

    def _navigate(self, goal_handle):  # noqa: ANN001, ANN202 - rclpy callback
        from merlin2_sailor.ros.navigation_interface import NavigationErrorCode, navigate_to_pose_type

        NavigateToPose = navigate_to_pose_type()  # noqa: N806 - a message type

        pose = goal_handle.request.pose.pose
        yaw = 2.0 * math.atan2(pose.orientation.z, pose.orientation.w)
        self.goals.append((round(pose.position.x, 3), round(pose.position.y, 3), yaw))
        if pose.position.x >= BLOCKING_X:
            self.driving.set()
            deadline = time.monotonic() + 10.0
            while not goal_handle.is_cancel_requested and time.monotonic() < deadline:
                time.sleep(0.02)
            if goal_handle.is_cancel_requested:
                self.cancelled.set()
                goal_handle.canceled()
                return NavigateToPose.Result(error_code=NavigationErrorCode.CANCELED)
            goal_handle.abort()
            return NavigateToPose.Result(error_code=NavigationErrorCode.TIMEOUT)
        self.pose = (pose.position.x, pose.position.y)
        goal_handle.succeed()
        return NavigateToPose.Result()

    def _get_anchors(self, request, response):  # noqa: ANN001, ANN202 - rclpy callback
        response.anchors = [a for a in self.anchors if not request.symbol or a.symbol == request.symbol]
        response.frame_id = "map"
        return response

    def _expect(self, request, response):  # noqa: ANN001, ANN202 - rclpy callback
        self.expectations.append((request.symbol, request.expectation, request.place, request.source,
                                  (request.position.x, request.position.y, request.position.z)))
        response.success = True
        return response

    def close(self) -> None:
        import rclpy

        self._executor.shutdown()
        rclpy.try_shutdown(context=self.context)
        self._thread.join(timeout=5.0)
        self.node.destroy_node()


def wait_until(condition, timeout: float = 20.0) -> bool:  # noqa: ANN001
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.05)
    return condition()


def test_behaviors_register_run_cancel_and_withdraw(node_process, ros_probe, tmp_path: Path) -> None:
    from merlin2_sailor.knowledge import PddlObject, PddlType, Proposition, Provenance
    from merlin2_sailor.ros.stores import open_store
    from merlin2_sailor_behaviors.actions import REASON_KEY
    from merlin2_sailor_behaviors.catalogue import SAILOR_ACTIONS
    from merlin2_sailor_behaviors.ros.pddl_action_client import RemoteBehaviours
    from merlin2_sailor_behaviors.state_machines import ABORT, CANCEL, SUCCEED
    from merlin2_sailor_interfaces.msg import Anchor
    from merlin2_sailor_interfaces.srv import ExpectAnchor

    tag = uuid.uuid4().hex[:8]
    namespace, world, node_name = f"/kb_{tag}", f"/world_{tag}", f"behaviors_{tag}"
    grounding = tmp_path / "grounding.yaml"
    grounding.write_text(GROUNDING, encoding="utf-8")
    robot = StandInRobot(world)
    cup = Anchor(symbol="cup_1", class_name="cup", state=Anchor.STATE_CONFIRMED)
    cup.position.x, cup.position.y, cup.position.z = 2.3, 0.2, 0.8
    robot.anchors.append(cup)
    node_process("knowledge_base", "--ros-args", "-r", f"__ns:={namespace}", "-p", "store:=memory")
    behaviors = node_process(
        "behaviors", "--ros-args", "-r", f"__node:={node_name}",
        "-p", f"knowledge_base:=ros://{namespace}", "-p", f"grounding:={grounding}",
        "-p", f"anchoring:={world}/anchoring", "-p", f"navigation_action:={world}/navigate_to_pose",
        "-p", f"robot_pose_topic:={world}/robot_pose", "-p", "look_dwell:=0.0",
        "-p", "registration_retry_period:=0.2")
    store = open_store(f"ros://{namespace}")
    viewer_messages = _optional("yasmin_msgs.msg")
    try:
        def actions() -> set[str]:
            return {action.name for action in store.actions.get_all()}

        assert wait_until(lambda: actions() == set(SAILOR_ACTIONS)), behaviors.text
        assert wait_until(lambda: store.propositions.get(("robot_at", ("a",), False)) is not None), behaviors.text
        assert {o.name for o in store.objects.get_all()} >= {"a", "b", "c"}  # the map's places
        store.types.save(PddlType("cup"))
        store.objects.save(PddlObject("cup_1", "cup"))
        store.propositions.save(Proposition("object_at", ("cup_1", "b"), provenance=Provenance.PERCEIVED))

        with RemoteBehaviours(store, prefix=f"/{node_name}", discovery_timeout=10.0) as remote:
            assert set(remote.behaviours) == set(SAILOR_ACTIONS)
            navigation = remote.behaviours["navigation"]

            blackboard = SAILOR_ACTIONS["navigation"].blackboard_for(("a", "b"))
            assert navigation(blackboard) == SUCCEED, blackboard[REASON_KEY] if REASON_KEY in blackboard else ""
            assert robot.goals[0][:2] == (2.0, 0.0) and len(robot.goals) == 5  # there, then four turns
            assert robot.expectations == [("cup_1", ExpectAnchor.Request.EXPECT_AT, "b", "navigation",
                                           pytest.approx((2.3, 0.2, 0.8)))]
            assert navigation.last_state  # feedback named the states it entered

            blackboard = SAILOR_ACTIONS["navigation"].blackboard_for(("b", "c"))
            outcomes: list[str] = []
            runner = threading.Thread(target=lambda: outcomes.append(navigation(blackboard)))
            runner.start()
            assert robot.driving.wait(10.0)
            if viewer_messages is not None:  # where YASMIN's messages are installed, the viewer sees the run
                layouts = ros_probe.collect(viewer_messages.StateMachine, "/fsm_viewer", 1, 10, timeout=10.0)
                assert layouts and layouts[0].states[0].name == "navigation", behaviors.text
                root = layouts[0].states[0]
                assert root.is_fsm and root.current_state > 0
            navigation.cancel_state()
            runner.join(10.0)
            assert outcomes == [CANCEL] and robot.cancelled.is_set(), blackboard[REASON_KEY]

            blackboard = SAILOR_ACTIONS["navigation"].blackboard_for(("b", "attic"))
            assert navigation(blackboard) == ABORT and "unknown place 'attic'" in blackboard[REASON_KEY]
    finally:
        exit_code = behaviors.stop()
        robot.close()
    try:
        assert exit_code == 0, behaviors.text
        assert "Traceback" not in behaviors.text, behaviors.text
        assert store.actions.get_all() == ()  # withdrawn when the node stopped
        assert store.predicates.get("robot_at") is not None  # declarations stay for the facts
    finally:
        store.close()


def _optional(module_name: str):  # noqa: ANN202
    """The module, or None where it is not installed (yasmin_msgs comes with SAILOR_UPSTREAM)."""
    import importlib

    try:
        return importlib.import_module(module_name)
    except ImportError:
        return None
