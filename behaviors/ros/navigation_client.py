"""NavigateToPose (Nav2's, or the simulated world's) and the robot's pose, as a
:class:`~merlin2_sailor_behaviors.actions.clients.NavigationPort`.

One goal at a time from the calling (worker) thread; cancelling the behaviour cancels the goal on
the server. A goal that runs past ``goal_timeout`` is cancelled and reported as failed; a result
lost on the way is asked for again. The robot pose comes from a ``PoseStamped`` topic
(``robot_pose``, as the anchoring node reads it); a pose that is not finite is dropped with a
warning.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from action_msgs.msg import GoalStatus
from geometry_msgs.msg import PoseStamped
from rclpy.callback_groups import CallbackGroup
from rclpy.node import Node

from merlin2_sailor.ros.action_client import RaceFreeActionClient
from merlin2_sailor.ros.qos import SENSOR_DATA
from merlin2_sailor_behaviors.actions.clients import NavigationResult, NavigationStatus, Pose2D
from merlin2_sailor_behaviors.actions.errors import BehaviorError
from merlin2_sailor_behaviors.ros.conversions import planar_pose, pose_stamped
from merlin2_sailor_behaviors.ros.waiting import WaitEnd, wait_for, wait_for_future, wait_for_goal_result
from merlin2_sailor_interfaces.action import NavigateToPose

STOPPING = NavigationResult(NavigationStatus.FAILED, "the behaviors node is shutting down")


class RosNavigationClient:
    """Sends NavigateToPose goals to ``action_name`` and follows ``robot_pose_topic``."""

    def __init__(
        self,
        node: Node,
        stopping: threading.Event,
        action_name: str = "navigate_to_pose",
        robot_pose_topic: str = "robot_pose",
        frame_id: str = "map",
        server_timeout: float = 5.0,
        goal_timeout: float = 300.0,
        callback_group: CallbackGroup | None = None,
    ) -> None:
        self._node = node
        self._stopping = stopping
        self._frame_id = frame_id
        self._server_timeout = server_timeout
        self._goal_timeout = goal_timeout
        self._client = RaceFreeActionClient(node, NavigateToPose, action_name, callback_group=callback_group)
        namespace = node.get_namespace().rstrip("/")
        self._action_name = action_name if action_name.startswith("/") else f"{namespace}/{action_name}"
        self._pose: Pose2D | None = None
        self._pose_lock = threading.Lock()
        node.create_subscription(PoseStamped, robot_pose_topic, self._on_pose, SENSOR_DATA,
                                 callback_group=callback_group)

    @property
    def action_name(self) -> str:
        """The action's name, with the node's namespace when it was given relative."""
        return self._action_name

    def robot_pose(self) -> Pose2D | None:
        with self._pose_lock:
            return self._pose

    def _on_pose(self, message: PoseStamped) -> None:
        try:
            pose = planar_pose(message)
        except BehaviorError as error:
            self._node.get_logger().warning(f"dropped a robot pose: {error}", throttle_duration_sec=5.0)
            return
        with self._pose_lock:
            self._pose = pose

    def navigate(self, goal: Pose2D, should_cancel: Callable[[], bool]) -> NavigationResult:
        end = wait_for(self._client.server_is_ready, self._server_timeout, self._stopping, should_cancel)
        if end is WaitEnd.CANCELED:
            return NavigationResult(NavigationStatus.CANCELED)
        if end is WaitEnd.STOPPING:
            return STOPPING
        if end is WaitEnd.TIMEOUT:
            raise BehaviorError(
                f"no NavigateToPose server at {self.action_name} after {self._server_timeout:g} s; "
                "is the navigation (Nav2 or the simulated world) running?"
            )
        request = NavigateToPose.Goal(pose=pose_stamped(goal, self._frame_id))
        request.pose.header.stamp = self._node.get_clock().now().to_msg()
        sent = self._client.send_goal_async(request)
        end = wait_for_future(sent, self._server_timeout, self._stopping)
        if end is WaitEnd.STOPPING:
            return STOPPING
        if end is not WaitEnd.DONE or sent.result() is None:
            raise BehaviorError(f"{self.action_name} did not answer a goal within {self._server_timeout:g} s")
        handle = sent.result()
        if not handle.accepted:
            return NavigationResult(NavigationStatus.FAILED, f"{self.action_name} rejected the goal")
        waited = wait_for_goal_result(handle, self._goal_timeout, self._stopping, should_cancel)
        self._report_requeries(waited.requeries)
        if waited.end is not WaitEnd.DONE:
            handle.cancel_goal_async()
            if waited.end is WaitEnd.STOPPING:
                return STOPPING
            if waited.end is WaitEnd.TIMEOUT:
                return NavigationResult(
                    NavigationStatus.FAILED, f"the robot did not arrive within {self._goal_timeout:g} s")
            # Cancelled: give the server a moment to stop the robot and say so.
            self._report_requeries(wait_for_goal_result(handle, self._server_timeout, self._stopping).requeries)
            return NavigationResult(NavigationStatus.CANCELED)
        return self._outcome(waited.response, should_cancel)

    def _report_requeries(self, requeries: int) -> None:
        if requeries:
            self._node.get_logger().warning(
                f"a result of {self.action_name} was lost on the way; asked for it again ({requeries} time(s))")

    def _outcome(self, response: object, should_cancel: Callable[[], bool]) -> NavigationResult:
        status = getattr(response, "status", GoalStatus.STATUS_UNKNOWN)
        if status == GoalStatus.STATUS_SUCCEEDED:
            return NavigationResult(NavigationStatus.ARRIVED)
        if status == GoalStatus.STATUS_CANCELED and should_cancel():
            return NavigationResult(NavigationStatus.CANCELED)
        result = getattr(response, "result", None)
        code = getattr(result, "error_code", 0)
        text = getattr(result, "error_msg", "") or "no reason given"
        how = {GoalStatus.STATUS_ABORTED: "aborted", GoalStatus.STATUS_CANCELED: "cancelled"}.get(status, "ended")
        return NavigationResult(NavigationStatus.FAILED, f"{self.action_name} {how} the goal (error {code}: {text})")

    def destroy(self) -> None:
        self._client.destroy()
