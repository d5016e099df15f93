"""bag_recorder: record topics to a rosbag2 bag (MCAP or SQLite3), in place of ``ros2 bag record``.

``ros2 bag`` is not on PyPI; this node writes the same bags through ``rosbags``. It subscribes to
the listed topics as they appear (their types are learned from the graph), receives each message
as the serialised bytes DDS delivered and writes them unchanged, stamped with the time they
arrived, as ``ros2 bag record`` does. Each topic is subscribed with what its publishers offer
(reliable where they all are, transient-local where they all are: a latched topic such as
``anchors`` then gives its last message even when it was published before the recorder started).

The bag is closed when the node stops (Ctrl-C, the launch's end), and a summary line says what it
holds. A topic whose type has no installed definition is said once and left out.
"""

from __future__ import annotations

import time
from collections.abc import Sequence

from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from merlin2_sailor.ros.bags import BAG_STORAGES, BagWriter
from merlin2_sailor.ros.conversions import message_class
from merlin2_sailor.ros.node_runner import run_node
from merlin2_sailor.ros.parameters import declare_parameter

NODE_NAME = "bag_recorder"
#: What `sailor demo --record` records: the camera, the percepts, the anchors and the knowledge.
DEFAULT_TOPICS = (
    "/camera/color/image_raw", "/camera/depth/image_raw", "/camera/color/camera_info", "/camera/camera_pose",
    "/camera/detections", "/camera/percepts", "/tf", "/tf_static", "/robot_pose", "/odom",
    "/anchors", "/anchor_events", "/merlin2/knowledge_changes",
)
QUEUE_DEPTH = 100  # messages a subscription holds while the writer is busy (a burst of camera frames)


class BagRecorderNode(Node):
    def __init__(self) -> None:
        super().__init__(NODE_NAME)
        path = declare_parameter(self, "path", "", "Folder of the bag to create (it must not exist); empty: "
                                 "rosbag2_<date>-<time> in the working directory, as ros2 bag names it.")
        storage = declare_parameter(self, "storage", "mcap", f"Bag storage: {' or '.join(BAG_STORAGES)}.")
        topics = declare_parameter(self, "topics", list(DEFAULT_TOPICS),
                                   "Topics to record, as they appear (absolute, or relative to the namespace).")
        discovery_period = declare_parameter(self, "discovery_period", 0.5,
                                             "Seconds between two looks for listed topics not yet recorded.",
                                             minimum=0.05, maximum=60.0)
        path = path or time.strftime("rosbag2_%Y_%m_%d-%H_%M_%S")
        self._wanted = [self.resolve_topic_name(topic) for topic in topics if topic]
        self._writer = BagWriter(path, storage)
        self._subscribed: set[str] = set()
        self._left_out: set[str] = set()
        self._closed = False
        self.get_logger().info(f"recording {len(self._wanted)} topics to {self._writer.path} ({storage})")
        self.create_timer(discovery_period, self._discover)
        self._discover()

    def _discover(self) -> None:
        graph = dict(self.get_topic_names_and_types())
        for topic in self._wanted:
            if topic in self._subscribed or topic in self._left_out or topic not in graph:
                continue
            type_name = graph[topic][0]
            try:
                message_type = message_class(type_name)
                self._writer.add_topic(topic, type_name)
            except Exception as error:  # noqa: BLE001 - a topic that cannot be recorded must not end the others
                self.get_logger().error(f"not recording {topic}: {error}")
                self._left_out.add(topic)
                continue
            self.create_subscription(message_type, topic, lambda data, name=topic: self._write(name, data),
                                     self._qos_of(topic), raw=True)
            self._subscribed.add(topic)

    def _qos_of(self, topic: str) -> QoSProfile:
        offered = [info.qos_profile for info in self.get_publishers_info_by_topic(topic)]
        reliable = bool(offered) and all(qos.reliability == ReliabilityPolicy.RELIABLE for qos in offered)
        latched = bool(offered) and all(qos.durability == DurabilityPolicy.TRANSIENT_LOCAL for qos in offered)
        return QoSProfile(
            history=HistoryPolicy.KEEP_LAST, depth=QUEUE_DEPTH,
            reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
            durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE)

    def _write(self, topic: str, data: bytes) -> None:
        if not self._closed:
            self._writer.write(topic, self.get_clock().now().nanoseconds, data)

    def destroy_node(self) -> None:
        if not self._closed:
            self._closed = True
            self._writer.close()
            counts = ", ".join(f"{topic} {count}" for topic, count in sorted(self._writer.counts.items())) or "nothing"
            missing = sorted(set(self._wanted) - self._subscribed - self._left_out)
            self.get_logger().info(f"bag {self._writer.path} closed: {counts}"
                                   + (f"; never published: {', '.join(missing)}" if missing else ""))
        super().destroy_node()


def main(argv: Sequence[str] | None = None) -> int:
    return run_node(BagRecorderNode, argv)


if __name__ == "__main__":
    raise SystemExit(main())
