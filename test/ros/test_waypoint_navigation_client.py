"""The behaviours' navigation client with MERLIN2's waypoint navigation (waypoint_navigation_msgs).

A stand-in serves NavigateToWp (the interface of MERLIN2's waypoint_navigation node) and
NavigateToPose (Nav2's type where nav2_msgs is built) in this test's own context; the client runs
in another, as a behaviour's would. Skips, saying why, without SAILOR_UPSTREAM.
"""

from __future__ import annotations

import threading
import uuid

import pytest

pytestmark = pytest.mark.ros


class StandInNavigation:
    """NavigateToWp at ``<prefix>/navigate_to_wp`` (knowing ``known`` waypoints) and NavigateToPose at
    ``<prefix>/navigate_to_pose``; every goal is recorded."""

    def __init__(self, prefix: str, known: set[str]) -> None:
        import rclpy
        from rclpy.action import ActionServer
        from rclpy.executors import MultiThreadedExecutor
        from waypoint_navigation_msgs.action import NavigateToWp

        from merlin2_sailor.ros.navigation_interface import navigate_to_pose_type

        self.context = rclpy.Context()
        rclpy.init(context=self.context)
        self.node = rclpy.create_node(f"stand_in_navigation_{uuid.uuid4().hex[:6]}", context=self.context)
        self.known = known
        self.waypoint_goals: list[str] = []
        self.pose_goals: list[tuple[float, float]] = []
        self._waypoints = ActionServer(self.node, NavigateToWp, f"{prefix}/navigate_to_wp", self._to_waypoint)
        self._poses = ActionServer(self.node, navigate_to_pose_type(), f"{prefix}/navigate_to_pose", self._to_pose)
        self._result_types = (NavigateToWp.Result, navigate_to_pose_type().Result)
        self.executor = MultiThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self._thread = threading.Thread(target=self.executor.spin, daemon=True)
        self._thread.start()

    def _to_waypoint(self, goal_handle):  # noqa: ANN001, ANN202 - rclpy callback
        self.waypoint_goals.append(goal_handle.request.wp_id)
        if goal_handle.request.wp_id in self.known:
            goal_handle.succeed()
        else:
            goal_handle.abort()  # as MERLIN2's node does for a waypoint it does not know
        return self._result_types[0]()

    def _to_pose(self, goal_handle):  # noqa: ANN001, ANN202 - rclpy callback
        pose = goal_handle.request.pose.pose.position
        self.pose_goals.append((round(pose.x, 3), round(pose.y, 3)))
        goal_handle.succeed()
        return self._result_types[1]()

    def close(self) -> None:
        self.executor.shutdown()
        self._thread.join(timeout=5.0)
        self.node.destroy_node()
        self.context.try_shutdown()


@pytest.fixture
def stand_in(upstream_stack) -> StandInNavigation:
    upstream_stack("waypoint_navigation_msgs.action", "nav2_msgs.action")
    prefix = f"/wp_test_{uuid.uuid4().hex[:8]}"
    navigation = StandInNavigation(prefix, known={"kitchen"})
    navigation.prefix = prefix
    yield navigation
    navigation.close()


def test_waypoints_go_by_name_to_navigate_to_wp_and_other_poses_to_navigate_to_pose(stand_in, ros_probe) -> None:
    from merlin2_sailor_behaviors.actions.clients import NavigationStatus, Pose2D
    from merlin2_sailor_behaviors.ros.navigation_client import RosNavigationClient

    stopping = threading.Event()
    client = RosNavigationClient(ros_probe.node, stopping, f"{stand_in.prefix}/navigate_to_pose",
                                 server_timeout=20.0, goal_timeout=20.0,
                                 waypoint_action=f"{stand_in.prefix}/navigate_to_wp")
    try:
        never = lambda: False  # noqa: E731
        arrived = client.navigate(Pose2D(2.5, 2.0, 3.14), never, waypoint="kitchen")
        assert arrived.status is NavigationStatus.ARRIVED, arrived.message
        assert stand_in.waypoint_goals == ["kitchen"] and stand_in.pose_goals == []

        turned = client.navigate(Pose2D(2.5, 2.0, 1.57), never)  # a turn: no waypoint
        assert turned.status is NavigationStatus.ARRIVED, turned.message
        assert stand_in.pose_goals == [(2.5, 2.0)] and stand_in.waypoint_goals == ["kitchen"]

        unknown = client.navigate(Pose2D(9.0, 9.0), never, waypoint="attic")
        assert unknown.status is NavigationStatus.FAILED
        assert "waypoint 'attic'" in unknown.message and "aborted" in unknown.message
    finally:
        client.destroy()


def test_a_waypoint_navigation_that_is_not_installed_is_a_clear_configuration_error(ros_probe, monkeypatch) -> None:
    from merlin2_sailor.errors import ConfigurationError
    from merlin2_sailor_behaviors.ros import navigation_client

    monkeypatch.setattr(navigation_client, "waypoint_navigation_type", lambda: None)
    with pytest.raises(ConfigurationError, match="waypoint_navigation_msgs"):
        navigation_client.RosNavigationClient(ros_probe.node, threading.Event(), waypoint_action="/x/navigate_to_wp")
