"""How ``sailor`` MERLIN2 missions learn where the robot stands when KANT does not say: the first
pose on the robot-pose topic, heard without disturbing the mission node's executor.

The mission node is a simple_node: its executor spins on a thread of its own while the mission's
main thread asks for the pose. A subscription made and destroyed on that node while its executor
builds a wait set ends the executor's thread with rclpy's InvalidHandle, and the mission then never
hears MERLIN2's result (a CI run lost a real-MERLIN2 mission so).
"""

from __future__ import annotations

import threading
import time
import uuid

import pytest

pytestmark = pytest.mark.ros

ASKS = 60
"""Enough asks that a listener made and destroyed on the spinning node meets the race (it did
within 70 at a faster publishing rate in a reproduction, and within a few hundred at this one)."""


class SpinningMissionNode:
    """A node spun as simple_node spins one: a multi-threaded executor on a daemon thread, here
    publishing the robot's pose fast (each publication wakes the executor) and counting ticks."""

    def __init__(self, topic: str, period: float = 0.001) -> None:
        import rclpy
        from geometry_msgs.msg import PoseStamped
        from rclpy.executors import MultiThreadedExecutor

        from merlin2_sailor.ros.qos import SENSOR_DATA

        self.node = rclpy.create_node(f"mission_like_{uuid.uuid4().hex[:6]}")
        self.ticks = 0
        self.failure: list[BaseException] = []
        self._pose = PoseStamped()
        self._pose.pose.position.x, self._pose.pose.position.y = 1.25, -3.5
        publisher = self.node.create_publisher(PoseStamped, topic, SENSOR_DATA)
        self.node.create_timer(period, self._publish(publisher))
        self.executor = MultiThreadedExecutor()
        self.executor.add_node(self.node)
        self.thread = threading.Thread(target=self._spin, daemon=True)
        self.thread.start()

    def _publish(self, publisher):  # noqa: ANN001, ANN202 - an rclpy timer callback
        def tick() -> None:
            self.ticks += 1
            publisher.publish(self._pose)
        return tick

    def _spin(self) -> None:
        try:
            self.executor.spin()
        except BaseException as error:  # noqa: BLE001 - the test reports what ended the thread
            self.failure.append(error)

    def still_spinning(self, within: float = 5.0) -> bool:
        start = self.ticks
        deadline = time.monotonic() + within
        while time.monotonic() < deadline and self.ticks == start:
            time.sleep(0.01)
        return self.thread.is_alive() and self.ticks > start

    def close(self) -> None:
        self.executor.shutdown()
        self.thread.join(timeout=5.0)
        self.node.destroy_node()


@pytest.fixture
def mission_node():  # noqa: ANN201 - yields a SpinningMissionNode
    import rclpy

    rclpy.init()
    topic = f"/robot_pose_{uuid.uuid4().hex[:6]}"
    node = SpinningMissionNode(topic)
    node.topic = topic
    yield node
    node.close()
    rclpy.try_shutdown()


def test_asking_for_the_pose_again_and_again_leaves_the_mission_node_spinning(mission_node) -> None:
    from merlin2_sailor_behaviors.merlin2.mission import first_robot_pose

    for _ in range(ASKS):
        assert first_robot_pose(mission_node.topic, timeout=10.0) == (1.25, -3.5)
    assert mission_node.still_spinning(), mission_node.failure
    assert not mission_node.failure


def test_no_pose_within_the_deadline_is_none(mission_node) -> None:
    from merlin2_sailor_behaviors.merlin2.mission import first_robot_pose

    started = time.monotonic()
    assert first_robot_pose(f"{mission_node.topic}_nobody_publishes", timeout=0.5) is None
    assert time.monotonic() - started < 5.0
