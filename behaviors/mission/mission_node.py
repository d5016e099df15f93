"""The ``mission`` node: declares a mission's goals, plans over the knowledge base, runs the plan on
the behaviours' action servers, replans when the world disagrees, and exits with the outcome.

Exit code 0 when every goal holds, 1 when the mission failed or was cancelled, 2 for a
configuration error (bad goals, nothing to run them with in time). While it runs it prints the
running account: plans, steps and their outcomes, facts entering and leaving the knowledge base,
and the anchor events that matter (acquired, missing, reacquired after missing, retracted).
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from typing import Any

from rclpy.node import Node

from merlin2_sailor.errors import SailorError
from merlin2_sailor.knowledge import ChangeEvent, KnowledgeBase
from merlin2_sailor.ros.conversions.anchoring import EVENT_KIND_TO_MESSAGE
from merlin2_sailor.ros.node_runner import run_node
from merlin2_sailor.ros.parameters import declare_parameter
from merlin2_sailor.ros.qos import EVENTS
from merlin2_sailor.ros.stores import open_store
from merlin2_sailor_behaviors.mission.account import AnchorEventWording, describe_fact_changes
from merlin2_sailor_behaviors.mission.goals import parse_goals
from merlin2_sailor_behaviors.mission.session import ForwardToRosLogger, MissionSession, SessionConfig
from merlin2_sailor_interfaces.msg import AnchorEventArray

_KIND_NAMES = {number: kind.value for kind, number in EVENT_KIND_TO_MESSAGE.items()}


def anchor_event_lines(wording: AnchorEventWording, message: AnchorEventArray) -> list[str]:
    """The running-account lines of one AnchorEventArray (routine events give none)."""
    lines = []
    for event in message.events:
        reason = next((item.value for item in event.details if item.key == "reason"), "")
        line = wording.describe(_KIND_NAMES.get(event.kind, str(event.kind)), event.symbol, event.class_name, reason)
        if line:
            lines.append(line)
    return lines


def open_knowledge_base(location: str, timeout: float = 5.0) -> KnowledgeBase:
    """``ros:///merlin2`` (the knowledge_base node) or any location open_store knows."""
    return open_store(location, timeout=timeout)


class MissionNode(Node):
    """Runs one mission on a worker thread; sets ``exit_code`` when it ends (see run_node)."""

    def __init__(self, **options: Any) -> None:
        super().__init__("mission", **options)
        goals = declare_parameter(
            self, "goals", [""], "Goals of the mission, e.g. ['robot_near(cup_2)', 'explored(kitchen)'].")
        self._name = declare_parameter(self, "mission_name", "mission", "Name of the mission, for the logs.")
        location = declare_parameter(
            self, "knowledge_base", "ros:///merlin2", "Knowledge base to plan over (ros:///merlin2, sqlite://...).")
        actions = declare_parameter(
            self, "actions", [""], "Actions the mission may use, waited for before planning ([''] : every one).")
        config = SessionConfig(
            engine=declare_parameter(self, "engine", "aries", "unified-planning engine (aries, tamer, ...)."),
            planning_timeout=declare_parameter(
                self, "planning_timeout", 10.0, "Seconds the planner may search.", minimum=0.1, maximum=600.0),
            max_replans=declare_parameter(
                self, "max_replans", 3, "Replans before the mission gives up.", minimum=0, maximum=100),
            actions_timeout=declare_parameter(
                self, "actions_timeout", 60.0, "Seconds to wait for the knowledge base and the behaviours.",
                minimum=1.0, maximum=3600.0),
            behaviors_prefix=declare_parameter(
                self, "behaviors_prefix", "/behaviors", "Where the behaviours' action servers are."),
            actions=tuple(name for name in actions if name),
        )
        self.exit_code: int | None = None
        if not any(goal.strip() for goal in goals):
            # Nothing to do: say how to give it something, and idle until stopped.
            self.get_logger().warning("no goals given (e.g. -p \"goals:=['robot_at(kitchen)']\"): idle")
            self._worker = None
            return
        self._goals = parse_goals(goals)
        self._store = open_knowledge_base(location)
        self._session = MissionSession(self._store, self, config, self.get_logger().info)
        self._anchor_words = AnchorEventWording()
        self._unsubscribe = self._store.subscribe(self._on_fact_changes)
        self.create_subscription(AnchorEventArray, "/anchor_events", self._on_anchor_events, EVENTS)
        self._log_handler = ForwardToRosLogger(self)
        self._log_handler.attach()
        self._worker = threading.Thread(target=self._run, name="mission", daemon=True)
        self._worker.start()

    def _run(self) -> None:
        try:
            self._session.wait_until_ready()
            result = self._session.run(self._goals, self._name)
            self.exit_code = 0 if result.succeeded else 1
        except SailorError as error:
            self.get_logger().error(f"mission {self._name} cannot run: {error}")
            self.exit_code = 2

    def _on_fact_changes(self, events: Sequence[ChangeEvent]) -> None:
        for line in describe_fact_changes(events):
            self.get_logger().info(f"fact {line}")

    def _on_anchor_events(self, message: AnchorEventArray) -> None:
        for line in anchor_event_lines(self._anchor_words, message):
            self.get_logger().info(line)

    def destroy_node(self) -> None:
        if self._worker is None:
            super().destroy_node()
            return
        self._session.cancel()
        self._worker.join(timeout=10.0)
        self._session.close()
        self._log_handler.detach()
        self._unsubscribe()
        self._store.close()
        super().destroy_node()


def main(argv: Sequence[str] | None = None) -> int:
    return run_node(MissionNode, argv)
