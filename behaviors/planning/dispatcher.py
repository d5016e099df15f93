"""Runs plans step by step over the knowledge base, and replans when the world disagrees.

For each step: check its at-start conditions still hold, apply its at-start effects, run its
behaviour, and apply its at-end effects only when the behaviour succeeded. MERLIN2's dispatcher
applies at-end effects even after an abort, which tells the planner the robot reached a place it
never reached; here an aborted or cancelled step applies no at-end effect and its at-start
effects are undone (the action did not happen, so the state before it is the best estimate;
a behaviour that knows better writes the knowledge base itself, and the undo leaves facts
others changed alone).

Replanning happens when a step aborts, when a condition of the next step no longer holds, when
the plan ends without the goals holding, and when a fact the remaining plan relies on (see
:mod:`.reliance`) is retracted from the knowledge base, heard through ``store.subscribe``. If the
running step itself needs the retracted fact until its end, its behaviour is cancelled first.
After ``max_replans`` replans the mission gives up, with the last reason.

Plans are run sequentially, in order of planned start time, as MERLIN2's dispatcher does; a
domain that needs actions to overlap is outside what this runtime runs.
"""

import logging
import threading
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from enum import Enum
from typing import TypeVar

from merlin2_sailor.errors import ConfigurationError, KnowledgeError
from merlin2_sailor.knowledge import ChangeEvent, ItemKind, KnowledgeBase, Operation, Proposition
from merlin2_sailor_behaviors.planning.effects import (
    AnchoredTest,
    EffectWriter,
    anchored_by_provenance,
)
from merlin2_sailor_behaviors.planning.facts import FactKey, describe, fact_key, holds, unmet
from merlin2_sailor_behaviors.planning.grounding import GroundStep, ground_step
from merlin2_sailor_behaviors.planning.mission_result import MissionResult, MissionStatus
from merlin2_sailor_behaviors.planning.plan import Plan, PlanStep
from merlin2_sailor_behaviors.planning.planner import Planner, PlanningStatus
from merlin2_sailor_behaviors.planning.reliance import relied_on_facts
from merlin2_sailor_behaviors.planning.task import task_from_store
from merlin2_sailor_behaviors.state_machines import ABORT, CANCEL, SUCCEED, Blackboard

_logger = logging.getLogger(__name__)
_Result = TypeVar("_Result")

Behaviour = Callable[[Blackboard], str]
"""What runs a step: a state or state machine (called with the blackboard), or any callable
returning succeeded / aborted / canceled. If it has ``cancel_state()``, the runtime uses it."""

REASON_KEY = "reason"
"""Blackboard key where a behaviour that did not succeed may say why, in words."""

PLAN_STEP_KEY = "plan_step"
"""Blackboard key of the :class:`PlanStep` being run; each parameter is also a key, holding the
name of its object (``blackboard["destination"] == "kitchen"``)."""


@dataclass(frozen=True)
class DispatcherConfig:
    """How stubborn a mission is."""

    max_replans: int = 3

    def __post_init__(self) -> None:
        if self.max_replans < 0:
            raise ConfigurationError(f"max_replans must be 0 or more, got {self.max_replans}")


class _Ending(Enum):
    DONE = "done"
    REPLAN = "replan"
    FAILED = "failed"
    CANCELED = "canceled"


@dataclass(frozen=True)
class _Run:
    """How running one plan ended."""

    ending: _Ending
    reason: str = ""


class Dispatcher:
    """Plans with ``planner`` over ``store`` and runs each step with its behaviour.

    One mission at a time per dispatcher; :meth:`cancel` may be called from another thread.
    """

    def __init__(
        self,
        store: KnowledgeBase,
        planner: Planner,
        behaviours: Mapping[str, Behaviour],
        config: DispatcherConfig | None = None,
        is_anchored: AnchoredTest | None = None,
    ) -> None:
        self._store = store
        self._planner = planner
        self._behaviours = dict(behaviours)
        self._config = config or DispatcherConfig()
        self._effects = EffectWriter(store, is_anchored or anchored_by_provenance(store))
        self._lock = threading.RLock()
        self._relied_on: frozenset[FactKey] = frozenset()
        self._running_needs: frozenset[FactKey] = frozenset()
        self._running_behaviour: Behaviour | None = None
        self._retraction: str | None = None
        self._cancel_requested = threading.Event()
        self._writing_thread: int | None = None

    # Public.

    def run(self, goals: Sequence[Proposition]) -> MissionResult:
        """Reach ``goals`` (facts to make true), replanning as needed."""
        if not goals:
            raise ConfigurationError("a mission needs at least one goal")
        goal_facts = [fact_key(goal) for goal in goals]
        self._cancel_requested.clear()
        executed: list[PlanStep] = []
        plans: list[Plan] = []
        reason = ""
        unsubscribe = self._store.subscribe(self._on_changes)
        try:
            while True:
                if not unmet(self._store, goal_facts):
                    return MissionResult(
                        MissionStatus.SUCCEEDED, "every goal holds", tuple(executed), tuple(plans)
                    )
                if self._cancel_requested.is_set():
                    return MissionResult(
                        MissionStatus.CANCELED, "cancelled", tuple(executed), tuple(plans)
                    )
                if len(plans) > self._config.max_replans:
                    return MissionResult(
                        MissionStatus.FAILED,
                        f"gave up after {self._config.max_replans} replan(s); last: {reason}",
                        tuple(executed),
                        tuple(plans),
                    )
                vanished = vanished_objects(self._store, goals)
                if vanished:
                    return MissionResult(
                        MissionStatus.FAILED,
                        f"the goals name {', '.join(vanished)}, which the knowledge base no longer "
                        "holds (an anchor forgotten, or merged into another): no plan can reach them"
                        + (f" (after: {reason})" if reason else ""),
                        tuple(executed),
                        tuple(plans),
                    )
                task = task_from_store(self._store, goals, self._behaviours.keys())
                planned = self._planner.plan(task)
                if planned.status is not PlanningStatus.SOLVED or planned.plan is None:
                    missing = ", ".join(describe(g) for g in unmet(self._store, goal_facts))
                    why = f"no plan reaches {missing} with actions {list(task.actions)}"
                    if reason:
                        why += f" after: {reason}"
                    return MissionResult(
                        MissionStatus.FAILED,
                        f"{why} ({planned.reason})",
                        tuple(executed),
                        tuple(plans),
                    )
                plans.append(planned.plan)
                _logger.info("plan %d: %s", len(plans), planned.plan)
                run = self._run_plan(planned.plan, goal_facts, executed)
                if run.ending is _Ending.CANCELED:
                    return MissionResult(
                        MissionStatus.CANCELED, run.reason, tuple(executed), tuple(plans)
                    )
                if run.ending is _Ending.FAILED:
                    return MissionResult(
                        MissionStatus.FAILED, run.reason, tuple(executed), tuple(plans)
                    )
                if run.ending is _Ending.REPLAN:
                    reason = run.reason
                    _logger.info("replanning: %s", reason)
                else:
                    reason = "the plan ended but " + ", ".join(
                        describe(g) for g in unmet(self._store, goal_facts)
                    ) + " do(es) not hold"
        finally:
            unsubscribe()
            with self._lock:
                self._relied_on = frozenset()
                self._running_needs = frozenset()
                self._running_behaviour = None

    def cancel(self) -> None:
        """Stop the mission: the running behaviour is cancelled and nothing more is run."""
        self._cancel_requested.set()
        with self._lock:
            behaviour = self._running_behaviour
        self._cancel_behaviour(behaviour)

    # Running one plan.

    def _run_plan(
        self, plan: Plan, goals: list[FactKey], executed: list[PlanStep]
    ) -> _Run:
        try:
            steps = [self._ground(step) for step in plan.steps]
        except KnowledgeError as error:
            return _Run(_Ending.REPLAN, str(error))
        with self._lock:
            self._retraction = None
        for index, step in enumerate(steps):
            self._watch(relied_on_facts(steps[index:], goals), frozenset())
            if self._cancel_requested.is_set():
                return _Run(_Ending.CANCELED, "cancelled")
            if not unmet(self._store, goals):
                return _Run(_Ending.DONE)
            with self._lock:
                retraction = self._retraction
            if retraction:
                return _Run(_Ending.REPLAN, retraction)
            broken = self._broken_start_conditions(step)
            if broken:
                return _Run(_Ending.REPLAN, f"before {step.step}: {broken}")
            run = self._run_step(step, steps[index:], goals)
            if run.ending is not _Ending.DONE:
                return run
            executed.append(step.step)
        with self._lock:
            retraction = self._retraction
        return _Run(_Ending.REPLAN, retraction) if retraction else _Run(_Ending.DONE)

    def _run_step(self, step: GroundStep, remaining: list[GroundStep], goals: list[FactKey]) -> _Run:
        behaviour = self._behaviours[step.step.action]
        self._effects.remember_anchored(step.step.objects)
        applied = self._write(lambda: self._effects.apply(step.start_effects))
        needs = frozenset(
            literal.fact
            for literal in (*step.over_all_conditions, *step.end_conditions)
            if not literal.negative
        )
        self._watch(relied_on_facts(remaining, goals, first_step_started=True), needs)
        blackboard = Blackboard()
        for parameter, object_name in step.parameters.items():
            blackboard[parameter] = object_name
        blackboard[PLAN_STEP_KEY] = step.step
        with self._lock:
            self._running_behaviour = behaviour
        _logger.info("running %s", step.step)
        try:
            outcome = behaviour(blackboard)
        except Exception as error:  # a bug in a behaviour: replanning would only repeat it
            self._write(lambda: self._effects.undo(applied))
            # A machine cancelled between two of its states raises (YASMIN 3.2 does, and so does
            # the local implementation): a cancel this dispatcher made is still a cancel, not a bug.
            if self._cancel_requested.is_set():
                _logger.info("%s raised %r while being cancelled", step.step, error)
                return _Run(_Ending.CANCELED, f"cancelled during {step.step}")
            with self._lock:
                retraction = self._retraction
            if retraction is not None and step_was_cancelled(behaviour):
                _logger.info("%s raised %r while being cancelled for a retraction", step.step, error)
                return _Run(_Ending.REPLAN, retraction)
            return _Run(_Ending.FAILED, f"behaviour of {step.step} raised {error!r}")
        finally:
            with self._lock:
                self._running_behaviour = None
                self._running_needs = frozenset()
        reason = blackboard[REASON_KEY] if outcome != SUCCEED and REASON_KEY in blackboard else ""
        _logger.info("%s %s%s", step.step, outcome, f": {reason}" if reason else "")
        if outcome == SUCCEED:
            self._write(lambda: self._effects.apply(step.end_effects))
            return _Run(_Ending.DONE)
        if outcome not in (ABORT, CANCEL):
            self._write(lambda: self._effects.undo(applied))
            return _Run(
                _Ending.FAILED,
                f"behaviour of {step.step} returned {outcome!r}; it must return "
                f"{SUCCEED!r}, {ABORT!r} or {CANCEL!r}",
            )
        self._write(lambda: self._effects.undo(applied))
        if self._cancel_requested.is_set():
            return _Run(_Ending.CANCELED, f"cancelled during {step.step}")
        with self._lock:
            retraction = self._retraction
        # The behaviour's own reason says why (a search that found only look-alikes, say): keep it.
        return _Run(_Ending.REPLAN, retraction or f"{step.step} {outcome}" + (f": {reason}" if reason else ""))

    # Helpers.

    def _ground(self, step: PlanStep) -> GroundStep:
        action = self._store.actions.get(step.action)
        if action is None:
            raise KnowledgeError(f"action {step.action!r} left the knowledge base")
        return ground_step(action, step)

    def _broken_start_conditions(self, step: GroundStep) -> str:
        problems = [
            f"{describe(literal.fact)} {'holds' if literal.negative else 'no longer holds'}"
            for literal in step.start_conditions
            if holds(self._store, literal.fact) == literal.negative
        ]
        return "; ".join(problems)

    def _watch(self, relied_on: frozenset[FactKey], running_needs: frozenset[FactKey]) -> None:
        with self._lock:
            self._relied_on = relied_on
            self._running_needs = running_needs

    def _write(self, write: Callable[[], _Result]) -> _Result:
        """Run one of the runtime's own writes; its change events are not retractions."""
        with self._lock:
            self._writing_thread = threading.get_ident()
        try:
            return write()
        finally:
            with self._lock:
                self._writing_thread = None

    def _on_changes(self, events: Sequence[ChangeEvent]) -> None:
        with self._lock:
            if self._writing_thread == threading.get_ident():
                return
            retracted = [
                fact_key(event.item)
                for event in events
                if event.kind is ItemKind.PROPOSITION
                and event.operation is Operation.DELETE
                and isinstance(event.item, Proposition)
                and not event.item.is_goal
                and fact_key(event.item) in self._relied_on
            ]
            if not retracted:
                return
            if self._retraction is None:
                self._retraction = "the plan relied on " + ", ".join(
                    describe(fact) for fact in retracted
                ) + ", which was retracted"
            behaviour = (
                self._running_behaviour
                if any(fact in self._running_needs for fact in retracted)
                else None
            )
        self._cancel_behaviour(behaviour)

    @staticmethod
    def _cancel_behaviour(behaviour: Behaviour | None) -> None:
        cancel = getattr(behaviour, "cancel_state", None)
        if callable(cancel):
            cancel()


def step_was_cancelled(behaviour: Behaviour | None) -> bool:
    """Whether the behaviour was cancelled during its run (states and machines say so)."""
    is_canceled = getattr(behaviour, "is_canceled", None)
    return bool(is_canceled()) if callable(is_canceled) else False


def vanished_objects(store: KnowledgeBase, goals: Sequence[Proposition]) -> list[str]:
    """The objects ``goals`` name that the knowledge base does not hold (any more).

    An anchor merged into another, or forgotten, takes its object and every fact naming it out
    of the knowledge base while a mission may still aim at it; a problem naming it cannot be
    planned (the PDDL reader refuses an undeclared object), so the mission ends with the reason.
    """
    named = {name for goal in goals for name in goal.objects}
    held = {pddl_object.name for pddl_object in store.objects.get_all()}
    return sorted(named - held)
