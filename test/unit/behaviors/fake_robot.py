"""Fakes of the ports behaviours use (navigation, anchoring, gripper), and a small world for them.

The fake world has four waypoints on a line and a corner::

    a (0, 0) --- b (2, 0) --- c (5, 0)
                 |
                 d (2, 3)

Navigation arrives at once (or fails, or blocks until cancelled, when told to) and records every
goal. The fake anchoring layer holds anchor reports, records every expectation and, like the real
one, moves an anchor to where it is expected. ``world`` says where objects really are: when the
robot arrives at or turns at a pose within reach of one, its anchor is seen (confirmed, newer
last_seen), as the camera would make it.
"""

from __future__ import annotations

import itertools
import math
import threading
from collections.abc import Callable
from dataclasses import dataclass, field, replace

from merlin2_sailor.anchoring.anchor import AnchorState
from merlin2_sailor.knowledge import KnowledgeBase, PddlObject, PddlType, open_store
from merlin2_sailor_behaviors.actions import (
    AnchorReport,
    BehaviorConfig,
    BehaviorContext,
    BehaviorError,
    GraspResult,
    NavigationResult,
    NavigationStatus,
    Place,
    Places,
    Pose2D,
)
from merlin2_sailor_behaviors.catalogue import SAILOR_ACTIONS

WAYPOINTS = {"a": (0.0, 0.0), "b": (2.0, 0.0), "c": (5.0, 0.0), "d": (2.0, 3.0)}

START_POSE = Pose2D(0.0, 0.0, 0.0)

FAST = BehaviorConfig(
    look_around_turns=4,
    look_dwell=0.0,
    approach_timeout=0.2,
    reacquire_timeout=0.05,
    confirm_timeout=0.05,
    poll_period=0.01,
)


class FakeNavigation:
    """Arrives at every goal at once, unless a goal is to fail or to block until cancelled."""

    def __init__(self, pose: Pose2D | None = START_POSE) -> None:
        self.pose = pose
        self.goals: list[Pose2D] = []
        self.waypoints: list[str] = []
        """The waypoint each goal named ("" when the goal was no waypoint)."""
        self.unreachable: set[tuple[float, float]] = set()
        self.block = False
        self.started = threading.Event()
        self.cancelled = threading.Event()
        self.on_arrival: list[Callable[[Pose2D], None]] = []

    def navigate(self, goal: Pose2D, should_cancel: Callable[[], bool], waypoint: str = "") -> NavigationResult:
        self.goals.append(goal)
        self.waypoints.append(waypoint)
        self.started.set()
        if self.block:
            for _ in range(500):
                if should_cancel():
                    self.cancelled.set()
                    return NavigationResult(NavigationStatus.CANCELED, "cancelled")
                threading.Event().wait(0.01)
            return NavigationResult(NavigationStatus.FAILED, "the test never cancelled")
        if (round(goal.x, 3), round(goal.y, 3)) in self.unreachable:
            return NavigationResult(NavigationStatus.FAILED, "no path")
        self.pose = goal
        for listener in self.on_arrival:
            listener(goal)
        return NavigationResult(NavigationStatus.ARRIVED)

    def robot_pose(self) -> Pose2D | None:
        return self.pose

    def positions(self) -> list[tuple[float, float]]:
        return [(round(goal.x, 3), round(goal.y, 3)) for goal in self.goals]


@dataclass
class Expectation:
    kind: str
    symbol: str
    position: tuple[float, float, float]
    place: str = ""
    source: str = ""
    radius: float = 0.0


@dataclass
class FakeAnchoring:
    """Anchor reports by symbol; records expectations; raises BehaviorError when ``down``."""

    anchors: dict[str, AnchorReport] = field(default_factory=dict)
    expectations: list[Expectation] = field(default_factory=list)
    down: bool = False
    refuse_conclusions: bool = False
    """conclude_search answers False whatever the reports say (the anchoring layer did not take it)."""
    left_in_question: tuple[str, ...] = ()
    """What a search concluded with no candidate leaves in question: the anchoring layer then reports
    the sought anchor indistinguishable from these (empty: not found)."""
    alone_in_question: str = ""
    """What a search concluded with no candidate leaves alone in question, with no copy of the
    sought anchor: the anchoring layer then reports it found by look alone (empty: none)."""
    _clock: itertools.count = field(default_factory=lambda: itertools.count(100))

    def add(self, symbol: str, class_name: str, position: tuple[float, float, float],
            state: AnchorState = AnchorState.CONFIRMED) -> AnchorReport:
        report = AnchorReport(symbol, class_name, state, position, last_seen=float(next(self._clock)))
        self.anchors[symbol] = report
        return report

    def see(self, symbol: str, position: tuple[float, float, float] | None = None) -> None:
        """The camera perceives the object: confirmed, seen now (and there, when given)."""
        report = self.anchors[symbol]
        self.anchors[symbol] = replace(
            report, state=AnchorState.CONFIRMED, last_seen=float(next(self._clock)),
            position=position or report.position, times_seen=report.times_seen + 1)

    def report(self, symbol: str, found_by_look_alone: str | None = None,
               indistinguishable_from: tuple[str, ...] | None = None) -> None:
        """Set what the anchoring layer reports about a missing anchor's search (None: unchanged)."""
        report = self.anchors[symbol]
        self.anchors[symbol] = replace(
            report,
            found_by_look_alone=report.found_by_look_alone if found_by_look_alone is None else found_by_look_alone,
            indistinguishable_from=(
                report.indistinguishable_from if indistinguishable_from is None else indistinguishable_from),
        )

    def _check(self) -> None:
        if self.down:
            raise BehaviorError("service /anchoring/get_anchors is not available; is the anchoring node running?")

    def get_anchor(self, symbol: str) -> AnchorReport | None:
        self._check()
        return self.anchors.get(symbol)

    def get_anchors(self, class_name: str = "") -> tuple[AnchorReport, ...]:
        self._check()
        return tuple(a for a in self.anchors.values() if not class_name or a.class_name == class_name)

    def find_anchor(self, symbol: str = "", class_name: str = "",
                    near: tuple[float, float, float] | None = None) -> AnchorReport | None:
        self._check()
        if symbol:
            return self.anchors.get(symbol)
        candidates = self.get_anchors(class_name)
        if near is None:
            return candidates[0] if candidates else None
        return min(candidates, key=lambda a: math.dist(a.position, near), default=None)

    def expect_at(
        self, symbol: str, position: tuple[float, float, float], place: str, source: str, radius: float = 0.0
    ) -> None:
        self._check()
        self.expectations.append(Expectation("at", symbol, tuple(position), place, source, radius))
        if symbol in self.anchors:
            self.anchors[symbol] = replace(self.anchors[symbol], position=tuple(position))

    def expect_carried(self, symbol: str, offset: tuple[float, float, float], source: str) -> None:
        self._check()
        self.expectations.append(Expectation("carried", symbol, tuple(offset), "", source))

    def clear_expectation(self, symbol: str, source: str) -> None:
        self._check()
        self.expectations.append(Expectation("clear", symbol, (0.0, 0.0, 0.0), "", source))

    def conclude_search(self, symbol: str, source: str) -> bool:
        """Like the real one: the candidate found by look alone becomes the sought anchor (confirmed
        where the candidate is, seen now; the candidate's report is gone), unless a copy turned up;
        with no candidate, the anchors ``left_in_question`` make the sought one indistinguishable,
        or the one ``alone_in_question`` becomes its candidate."""
        self._check()
        self.expectations.append(Expectation("conclude", symbol, (0.0, 0.0, 0.0), "", source))
        sought = self.anchors.get(symbol)
        if sought is not None and not sought.found_by_look_alone and self.left_in_question:
            self.report(symbol, indistinguishable_from=self.left_in_question)
            return False
        if sought is not None and not sought.found_by_look_alone and self.alone_in_question in self.anchors:
            self.report(symbol, found_by_look_alone=self.alone_in_question)
            return False
        if (self.refuse_conclusions or sought is None or sought.indistinguishable_from
                or sought.found_by_look_alone not in self.anchors):
            return False
        candidate = self.anchors.pop(sought.found_by_look_alone)
        self.anchors[symbol] = replace(sought, found_by_look_alone="")
        self.see(symbol, candidate.position)
        return True


@dataclass
class FakeGrasp:
    picks: list[tuple[str, tuple[float, float, float]]] = field(default_factory=list)
    places: list[tuple[float, float, float]] = field(default_factory=list)
    pick_result: GraspResult = field(default_factory=lambda: GraspResult(True))
    place_result: GraspResult = field(default_factory=lambda: GraspResult(True))

    def pick(self, class_name: str, target: tuple[float, float, float]) -> GraspResult:
        self.picks.append((class_name, tuple(target)))
        return self.pick_result

    def place(self, target: tuple[float, float, float]) -> GraspResult:
        self.places.append(tuple(target))
        return self.place_result


@dataclass
class FakeRobot:
    """A context over fakes, plus where objects really are (the camera sees them on arrival)."""

    store: KnowledgeBase
    navigation: FakeNavigation
    anchoring: FakeAnchoring
    grasp: FakeGrasp
    context: BehaviorContext
    world: dict[str, tuple[float, float]] = field(default_factory=dict)
    logs: list[tuple[str, str]] = field(default_factory=list)

    def camera_sees(self, pose: Pose2D) -> None:
        for symbol, (x, y) in self.world.items():
            if math.hypot(pose.x - x, pose.y - y) <= 1.0 and symbol in self.anchoring.anchors:
                z = self.anchoring.anchors[symbol].position[2]
                self.anchoring.see(symbol, (x, y, z))


def make_robot(config: BehaviorConfig = FAST, pose: Pose2D | None = START_POSE) -> FakeRobot:
    store = open_store("memory")
    for action in SAILOR_ACTIONS.values():
        action.register(store)
    store.types.save(PddlType("cup"))
    for name in WAYPOINTS:
        store.objects.save(PddlObject(name, "wp"))
    navigation, anchoring, grasp = FakeNavigation(pose), FakeAnchoring(), FakeGrasp()
    logs: list[tuple[str, str]] = []
    places = Places(Place(name, x, y) for name, (x, y) in WAYPOINTS.items())
    context = BehaviorContext(store, anchoring, navigation, grasp, places, config,
                              log=lambda level, message: logs.append((level, message)))
    robot = FakeRobot(store, navigation, anchoring, grasp, context, logs=logs)
    navigation.on_arrival.append(robot.camera_sees)
    return robot
