"""NavigateToPose (Nav2's where nav2_msgs is installed, else the project's subset, as
:mod:`merlin2_sailor.ros.navigation_interface` decides) and the robot's pose, as a
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

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.ros.action_client import RaceFreeActionClient
from merlin2_sailor.ros.navigation_interface import (
    navigate_to_pose_type,
    navigation_interface_name,
    waypoint_navigation_type,
)
from merlin2_sailor.ros.qos import SENSOR_DATA
from merlin2_sailor_behaviors.actions.clients import NavigationResult, NavigationStatus, Pose2D
from merlin2_sailor_behaviors.actions.errors import BehaviorError
from merlin2_sailor_behaviors.ros.conversions import planar_pose, pose_stamped
from merlin2_sailor_behaviors.ros.waiting import WaitEnd, wait_for, wait_for_future, wait_for_goal_result

STOPPING = NavigationResult(NavigationStatus.FAILED, "the behaviors node is shutting down")


class RosNavigationClient:
    """Sends NavigateToPose goals to ``action_name`` and follows ``robot_pose_topic``; with a
    ``waypoint_action``, goals that are waypoints of the map go to that NavigateToWp server by name
    (MERLIN2's waypoint navigation, which drives with the robot's own waypoint poses)."""

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
        waypoint_action: str = "",
    ) -> None:
        self._node = node
        self._stopping = stopping
        self._frame_id = frame_id
        self._server_timeout = server_timeout
        self._goal_timeout = goal_timeout
        self._type = navigate_to_pose_type()
        self._client = RaceFreeActionClient(node, self._type, action_name, callback_group=callback_group)
        namespace = node.get_namespace().rstrip("/")
        self._action_name = action_name if action_name.startswith("/") else f"{namespace}/{action_name}"
        self._waypoint_client: RaceFreeActionClient | None = None
        self._waypoint_action = waypoint_action
        if waypoint_action:
            waypoint_type = waypoint_navigation_type()
            if waypoint_type is None:
                raise ConfigurationError(
                    f"waypoint navigation at {waypoint_action!r} needs MERLIN2's waypoint_navigation_msgs, which "
                    "is not installed; build it in the workspace, or leave the waypoint navigation action empty "
                    "to drive to waypoints with NavigateToPose")
            self._waypoint_type = waypoint_type
            self._waypoint_client = RaceFreeActionClient(
                node, waypoint_type, waypoint_action, callback_group=callback_group)
        node.get_logger().info(
            f"driving with {navigation_interface_name()} at {self._action_name}"
            + (f"; to the map's waypoints by name with NavigateToWp at {waypoint_action}" if waypoint_action else ""))
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

    def navigate(self, goal: Pose2D, should_cancel: Callable[[], bool], waypoint: str = "") -> NavigationResult:
        if waypoint and self._waypoint_client is not None:
            request = self._waypoint_type.Goal(wp_id=waypoint)
            return self._run_goal(self._waypoint_client, self._waypoint_action, request, should_cancel,
                                  f"waypoint {waypoint!r}")
        request = self._type.Goal(pose=pose_stamped(goal, self._frame_id))
        request.pose.header.stamp = self._node.get_clock().now().to_msg()
        return self._run_goal(self._client, self._action_name, request, should_cancel, "the pose")

    def _run_goal(
        self, client: RaceFreeActionClient, action_name: str, request: object, should_cancel: Callable[[], bool],
        destination: str,
    ) -> NavigationResult:
        """One goal, sent and waited for, every wait with its deadline."""
        end = wait_for(client.server_is_ready, self._server_timeout, self._stopping, should_cancel)
        if end is WaitEnd.CANCELED:
            return NavigationResult(NavigationStatus.CANCELED)
        if end is WaitEnd.STOPPING:
            return STOPPING
        if end is WaitEnd.TIMEOUT:
            raise BehaviorError(
                f"no {type(request).__name__.removesuffix('_Goal')} server at {action_name} after "
                f"{self._server_timeout:g} s; is the navigation (Nav2, MERLIN2's waypoint navigation or the "
                "simulated world) running?"
            )
        sent = client.send_goal_async(request)
        end = wait_for_future(sent, self._server_timeout, self._stopping)
        if end is WaitEnd.STOPPING:
            return STOPPING
        if end is not WaitEnd.DONE or sent.result() is None:
            raise BehaviorError(f"{action_name} did not answer a goal within {self._server_timeout:g} s")
        handle = sent.result()
        if not handle.accepted:
            return NavigationResult(NavigationStatus.FAILED, f"{action_name} rejected the goal to {destination}")
        waited = wait_for_goal_result(handle, self._goal_timeout, self._stopping, should_cancel)
        self._report_requeries(action_name, waited.requeries)
        if waited.end is not WaitEnd.DONE:
            handle.cancel_goal_async()
            if waited.end is WaitEnd.STOPPING:
                return STOPPING
            if waited.end is WaitEnd.TIMEOUT:
                return NavigationResult(
                    NavigationStatus.FAILED, f"the robot did not arrive within {self._goal_timeout:g} s")
            # Cancelled: give the server a moment to stop the robot and say so.
            cancelled = wait_for_goal_result(handle, self._server_timeout, self._stopping)
            self._report_requeries(action_name, cancelled.requeries)
            return NavigationResult(NavigationStatus.CANCELED)
        return self._outcome(action_name, destination, waited.response, should_cancel)

    def _report_requeries(self, action_name: str, requeries: int) -> None:
        if requeries:
            self._node.get_logger().warning(
                f"a result of {action_name} was lost on the way; asked for it again ({requeries} time(s))")

    def _outcome(
        self, action_name: str, destination: str, response: object, should_cancel: Callable[[], bool],
    ) -> NavigationResult:
        status = getattr(response, "status", GoalStatus.STATUS_UNKNOWN)
        if status == GoalStatus.STATUS_SUCCEEDED:
            return NavigationResult(NavigationStatus.ARRIVED)
        if status == GoalStatus.STATUS_CANCELED and should_cancel():
            return NavigationResult(NavigationStatus.CANCELED)
        result = getattr(response, "result", None)
        how = {GoalStatus.STATUS_ABORTED: "aborted", GoalStatus.STATUS_CANCELED: "cancelled"}.get(status, "ended")
        if not hasattr(result, "error_code"):  # NavigateToWp's result says nothing
            return NavigationResult(
                NavigationStatus.FAILED,
                f"{action_name} {how} the goal to {destination} (it gives no reason: an unknown waypoint, or its "
                "NavigateToPose failed)")
        text = getattr(result, "error_msg", "") or "no reason given"
        return NavigationResult(
            NavigationStatus.FAILED,
            f"{action_name} {how} the goal to {destination} (error {result.error_code}: {text})")

    def destroy(self) -> None:
        self._client.destroy()
        if self._waypoint_client is not None:
            self._waypoint_client.destroy()
