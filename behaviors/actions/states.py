"""The states behaviours are assembled from: drive somewhere, look around, wait for a sighting.

Every state here is a :class:`BehaviorState`: its work is :meth:`BehaviorState.run`, a
:class:`~merlin2_sailor_behaviors.actions.errors.BehaviorError` or
:class:`~merlin2_sailor.errors.KnowledgeError` raised there ends it ``aborted`` with the error as
the blackboard's reason, and a cancellation ends it ``canceled`` whatever ``run`` returned.
Waiting is done in short slices, so a cancellation is seen within a few hundredths of a second.
"""

from __future__ import annotations

import math
import time
from abc import abstractmethod
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from merlin2_sailor.errors import KnowledgeError
from merlin2_sailor_behaviors.actions.clients import AnchorReport, NavigationStatus, Pose2D
from merlin2_sailor_behaviors.actions.context import BehaviorContext
from merlin2_sailor_behaviors.actions.errors import BehaviorError
from merlin2_sailor_behaviors.actions.keys import REASON_KEY, WARNINGS_KEY
from merlin2_sailor_behaviors.state_machines import ABORT, CANCEL, SUCCEED, Blackboard, State

BASIC = (SUCCEED, ABORT, CANCEL)

CANCEL_CHECK_SECONDS = 0.02
"""Longest a waiting state sleeps between two looks at its cancellation flag."""


@dataclass(frozen=True)
class Target:
    """Where to drive: a pose, and a name for it in messages (a waypoint, "cup_1")."""

    name: str
    pose: Pose2D
    waypoint: str = ""
    """The map's name of this place when it is one of its waypoints: a robot with a waypoint
    navigation (MERLIN2's NavigateToWp) is sent there by name, with the waypoint's own pose."""


def abort(blackboard: Blackboard, reason: str) -> str:
    """Record why on the blackboard and return ``aborted``."""
    blackboard[REASON_KEY] = reason
    return ABORT


def warn(context: BehaviorContext, blackboard: Blackboard, message: str) -> None:
    """Log something that went wrong without stopping the behaviour, and keep it for the result."""
    context.log("warning", message)
    warnings = list(blackboard[WARNINGS_KEY]) if WARNINGS_KEY in blackboard else []
    blackboard[WARNINGS_KEY] = [*warnings, message]


def pause(seconds: float, state: State) -> bool:
    """Sleep ``seconds`` unless ``state`` is cancelled first; True when it slept it all."""
    deadline = time.monotonic() + seconds
    while not state.is_canceled():
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            return True
        time.sleep(min(CANCEL_CHECK_SECONDS, remaining))
    return False


def wait_until(condition: Callable[[], bool], timeout: float, period: float, state: State) -> bool:
    """Ask ``condition`` every ``period`` seconds for up to ``timeout``; True once it holds.

    Returns False on timeout or when ``state`` is cancelled (the caller checks which).
    """
    deadline = time.monotonic() + timeout
    while True:
        if condition():
            return True
        remaining = deadline - time.monotonic()
        if remaining <= 0 or state.is_canceled():
            return False
        if not pause(min(period, remaining), state):
            return False


class BehaviorState(State):
    """A state with its context; subclasses implement :meth:`run`."""

    def __init__(self, context: BehaviorContext, outcomes: Iterable[str] = BASIC) -> None:
        super().__init__(list(outcomes))
        self.context = context

    @abstractmethod
    def run(self, blackboard: Blackboard) -> str:
        """Do the work; raise BehaviorError (or KnowledgeError) to abort with its message."""

    def execute(self, blackboard: Blackboard) -> str:
        try:
            outcome = self.run(blackboard)
        except (BehaviorError, KnowledgeError) as error:
            outcome = abort(blackboard, str(error))
        if self.is_canceled() and CANCEL in self.get_outcomes():
            return CANCEL
        return outcome


class CallbackState(BehaviorState):
    """A :class:`BehaviorState` whose work is a function: ``callback(state, blackboard)``."""

    def __init__(
        self,
        context: BehaviorContext,
        callback: Callable[[BehaviorState, Blackboard], str],
        outcomes: Iterable[str] = BASIC,
    ) -> None:
        super().__init__(context, outcomes)
        self._callback = callback

    def run(self, blackboard: Blackboard) -> str:
        return self._callback(self, blackboard)

    def __str__(self) -> str:
        return f"CallbackState({getattr(self._callback, '__name__', '?')})"


class GoTo(BehaviorState):
    """Drive to the :class:`Target` under ``blackboard[target_key]``; the goal is cancelled with
    the state.

    A drive that fails aborts; with ``failed_outcome`` set to another outcome (declared for
    it), the failure is a warning and the state ends with that outcome instead.
    """

    def __init__(self, context: BehaviorContext, target_key: str, failed_outcome: str = ABORT) -> None:
        super().__init__(context, BASIC if failed_outcome == ABORT else (*BASIC, failed_outcome))
        self._target_key = target_key
        self._failed_outcome = failed_outcome

    def run(self, blackboard: Blackboard) -> str:
        target: Target = blackboard[self._target_key]
        outcome, why = drive(self, target)
        if outcome != ABORT:
            return outcome
        if self._failed_outcome == ABORT:
            return abort(blackboard, why)
        warn(self.context, blackboard, why)
        return self._failed_outcome


def drive(state: BehaviorState, target: Target) -> tuple[str, str]:
    """Send one NavigateToPose goal from ``state``; its outcome, and why when it aborted."""
    result = state.context.navigation.navigate(target.pose, state.is_canceled, target.waypoint)
    if result.status is NavigationStatus.ARRIVED:
        return SUCCEED, ""
    if result.status is NavigationStatus.CANCELED or state.is_canceled():
        return CANCEL, ""
    pose = target.pose
    return ABORT, (
        f"could not reach {target.name} ({pose.x:.2f}, {pose.y:.2f}, yaw {pose.yaw:.2f}): "
        f"{result.message or 'the navigation gave no reason'}"
    )


class LookAround(BehaviorState):
    """Turn in place through 360 degrees at ``blackboard[target_key]``, so the camera sweeps it.

    ``look_around_turns`` goals at the same position, each a full turn's share further, with
    ``look_dwell`` seconds of stillness after each; with 0 turns it only dwells. ``stop_when``
    (asked after each dwell) ends the look early. When ``required`` is False, a turn that fails is
    a warning and the look goes on; when True it aborts.
    """

    def __init__(
        self,
        context: BehaviorContext,
        target_key: str,
        required: bool = True,
        stop_when: Callable[[Blackboard], bool] | None = None,
    ) -> None:
        super().__init__(context)
        self._target_key = target_key
        self._required = required
        self._stop_when = stop_when

    def run(self, blackboard: Blackboard) -> str:
        target: Target = blackboard[self._target_key]
        config = self.context.config
        if self._stop_when is not None and self._stop_when(blackboard):
            return SUCCEED
        turns = config.look_around_turns
        if turns == 0:
            if not pause(config.look_dwell, self):
                return CANCEL
            self._record(target)
            return SUCCEED
        self.context.looks.forget()  # from the first turn on, the robot no longer looks as it did
        for turn in range(1, turns + 1):
            heading = target.pose.turned(turn * 2.0 * math.pi / turns)
            outcome, why = drive(self, Target(f"{target.name} (turn {turn}/{turns})", heading))
            if outcome == CANCEL:
                return CANCEL
            if outcome == ABORT:
                if self._required:
                    return abort(blackboard, f"looking around at {target.name}: {why}")
                warn(self.context, blackboard, f"looking around at {target.name}: {why}")
            if not pause(config.look_dwell, self):
                return CANCEL
            if self._stop_when is not None and self._stop_when(blackboard):
                return SUCCEED
        self._record(target)
        return SUCCEED

    def _record(self, target: Target) -> None:
        self.context.looks.record(target.name, target.pose.x, target.pose.y)


def place_target(context: BehaviorContext, place_name: str) -> Target:
    """Where to drive to reach a named place: its position, heading its own ``yaw`` when the map
    gives one, else the way the robot arrives (from where it is now), else 0.

    Raises:
        BehaviorError: the map has no such place.
    """
    place = context.places.get(place_name)
    waypoint = place.name if place.is_waypoint else ""  # a region's centre is driven to as a pose
    if place.yaw is not None:
        return Target(place.name, Pose2D(place.x, place.y, place.yaw), waypoint)
    robot = context.navigation.robot_pose()
    if robot is None:
        return Target(place.name, Pose2D(place.x, place.y, 0.0), waypoint)
    arrival = Pose2D(robot.x, robot.y, robot.yaw).facing(place.x, place.y)
    return Target(place.name, Pose2D(place.x, place.y, arrival.yaw), waypoint)


def robot_pose_or(context: BehaviorContext, place_name: str) -> Pose2D:
    """The robot's pose, or the named place's when no pose has arrived (the robot is there)."""
    robot = context.navigation.robot_pose()
    if robot is not None:
        return robot
    place = context.places.get(place_name)
    return Pose2D(place.x, place.y, place.yaw or 0.0)


def require_anchor(context: BehaviorContext, symbol: str) -> AnchorReport:
    """The anchor of ``symbol``, or a BehaviorError saying the anchoring layer has none."""
    anchor = context.anchoring.get_anchor(symbol)
    if anchor is None:
        raise BehaviorError(
            f"the anchoring layer has no anchor {symbol!r}: it was never anchored or has been forgotten"
        )
    return anchor
