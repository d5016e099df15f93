"""topic_monitor: log the rate and latency of topics, in place of ``ros2 topic hz``.

It subscribes to the listed topics (or, with an empty list, to every topic it discovers),
whatever their type, and logs one line per report period: each topic's rate and the mean age of
its messages (arrival time minus header stamp), which is the end-to-end latency of the pipeline
that produced them.
"""

from __future__ import annotations

import time
from collections.abc import Sequence

from rclpy.node import Node

from merlin2_sailor.diagnostics.topic_statistics import TopicStatistics
from merlin2_sailor.errors import InvalidInputError
from merlin2_sailor.ros.conversions import message_class, stamp_to_seconds
from merlin2_sailor.ros.node_runner import run_node
from merlin2_sailor.ros.parameters import declare_parameter
from merlin2_sailor.ros.qos import ANY_PUBLISHER

NODE_NAME = "topic_monitor"
_IGNORED_TOPICS = {"/rosout", "/parameter_events"}


class TopicMonitorNode(Node):
    def __init__(self) -> None:
        super().__init__(NODE_NAME)
        self._requested_topics: list[str] = list(declare_parameter(
            self, "topics", [""],
            "Topics to monitor (relative names resolve in the node's namespace); "
            "an empty list monitors every topic in the graph.",
        ))
        self._requested_topics = [topic for topic in self._requested_topics if topic]
        report_period = declare_parameter(
            self, "report_period", 2.0, "Seconds between two report lines.", minimum=0.1, maximum=3600.0
        )
        self._window = declare_parameter(
            self, "window", 5.0, "Seconds of history each rate is computed over.", minimum=0.1, maximum=3600.0
        )
        self._statistics: dict[str, TopicStatistics] = {}
        self._unusable: set[str] = set()
        self.create_timer(report_period, self._report)
        self.create_timer(1.0, self._discover)
        self._discover()

    def _discover(self) -> None:
        wanted = {self.resolve_topic_name(topic) for topic in self._requested_topics}
        for topic, types in self.get_topic_names_and_types():
            if topic in self._statistics or topic in self._unusable or topic in _IGNORED_TOPICS:
                continue
            if wanted and topic not in wanted:
                continue
            try:
                message_type = message_class(types[0])
            except InvalidInputError as error:
                self.get_logger().warning(f"cannot monitor {topic}: {error}")
                self._unusable.add(topic)
                continue
            statistics = TopicStatistics(self._window)
            self._statistics[topic] = statistics
            self.create_subscription(
                message_type, topic, lambda message, s=statistics: self._record(s, message), ANY_PUBLISHER
            )

    def _record(self, statistics: TopicStatistics, message: object) -> None:
        header = getattr(message, "header", None)
        stamp = stamp_to_seconds(header.stamp) if header is not None else None
        statistics.record(time.time(), stamp)

    def _report(self) -> None:
        now = time.time()
        missing = [
            topic for topic in (self.resolve_topic_name(t) for t in self._requested_topics)
            if topic not in self._statistics
        ]
        parts = []
        for topic in sorted(self._statistics):
            report = self._statistics[topic].report(now)
            age = f", age {report.mean_age_seconds * 1000.0:.0f} ms" if report.mean_age_seconds is not None else ""
            parts.append(f"{topic} {report.rate_hz:.1f} Hz ({report.total_messages} msgs{age})")
        parts += [f"{topic} not published yet" for topic in missing]
        self.get_logger().info(" | ".join(parts) if parts else "no topics yet")


def main(argv: Sequence[str] | None = None) -> int:
    return run_node(TopicMonitorNode, argv)


if __name__ == "__main__":
    raise SystemExit(main())
