"""The mission runtime end to end in memory: plan with Tamer, dispatch fake behaviours, replan.

The scene is four waypoints with two routes from ``a`` to ``d`` (via ``b`` or via ``c``) and a
cross link ``b <-> c``. Navigation is MERLIN2's durative action plus an at-start ``connected``
condition, so that a retracted corridor changes which plans exist.
"""

from __future__ import annotations

import dataclasses
import threading
from collections.abc import Callable, Iterator

import pytest

pytest.importorskip("up_aries", reason="the mission runtime plans with Aries: pip install up-aries")

from merlin2_sailor.knowledge import (  # noqa: E402
    Condition,
    Effect,
    KnowledgeBase,
    Parameter,
    PddlAction,
    PddlObject,
    PddlType,
    Predicate,
    Proposition,
    Provenance,
    open_store,
)
from merlin2_sailor_behaviors.planning import (  # noqa: E402
    PLAN_STEP_KEY,
    Dispatcher,
    DispatcherConfig,
    Mission,
    MissionRunner,
    MissionStatus,
    Planner,
    PlanStep,
)
from merlin2_sailor_behaviors.state_machines import (  # noqa: E402
    ABORT,
    CANCEL,
    SUCCEED,
    Blackboard,
    CbState,
    StateMachine,
)

from .waiting_state import WAIT_SECONDS, WaitForCancel

WAYPOINTS = ("a", "b", "c", "d")
CORRIDORS = (("a", "b"), ("a", "c"), ("b", "d"), ("c", "d"), ("b", "c"), ("c", "b"))


def navigation() -> PddlAction:
    return PddlAction(
        "navigation",
        (Parameter("origin", "wp"), Parameter("destination", "wp")),
        (
            Condition("robot_at", ("origin",), "at start"),
            Condition("connected", ("origin", "destination"), "at start"),
        ),
        (
            Effect("robot_at", ("origin",), "at start", is_negative=True),
            Effect("robot_at", ("destination",), "at end"),
        ),
    )


def push() -> PddlAction:
    """Push an object along a corridor: the robot and the object both end at the destination."""
    return PddlAction(
        "push",
        (Parameter("thing", "item"), Parameter("origin", "wp"), Parameter("destination", "wp")),
        (
            Condition("robot_at", ("origin",), "at start"),
            Condition("object_at", ("thing", "origin"), "at start"),
            Condition("connected", ("origin", "destination"), "at start"),
        ),
        (
            Effect("robot_at", ("origin",), "at start", is_negative=True),
            Effect("object_at", ("thing", "origin"), "at start", is_negative=True),
            Effect("robot_at", ("destination",), "at end"),
            Effect("object_at", ("thing", "destination"), "at end"),
        ),
    )


@pytest.fixture
def store() -> Iterator[KnowledgeBase]:
    with open_store("memory") as knowledge:
        knowledge.types.save(PddlType("wp"))
        knowledge.types.save(PddlType("item"))
        for name in WAYPOINTS:
            knowledge.objects.save(PddlObject(name, "wp"))
        knowledge.predicates.save(Predicate("robot_at", ("wp",)))
        knowledge.predicates.save(Predicate("connected", ("wp", "wp")))
        knowledge.predicates.save(Predicate("object_at", ("item", "wp")))
        knowledge.actions.save(navigation())
        for origin, destination in CORRIDORS:
            knowledge.propositions.save(Proposition("connected", (origin, destination)))
        knowledge.propositions.save(Proposition("robot_at", ("a",)))
        yield knowledge


@pytest.fixture(scope="module")
def planner() -> Planner:
    return Planner()  # one unified-planning environment for the module: it takes ~1 s to make


def robot_at(store: KnowledgeBase) -> list[str]:
    facts = store.propositions.get_all()
    return sorted(p.objects[0] for p in facts if p.predicate == "robot_at" and not p.is_goal)


def goal(*waypoint: str) -> Mission:
    return Mission(tuple(Proposition("robot_at", (w,)) for w in waypoint))


def succeed(blackboard: Blackboard) -> str:
    return SUCCEED


def runner(
    store: KnowledgeBase,
    planner: Planner,
    behaviour: Callable[[Blackboard], str],
    max_replans: int = 3,
) -> MissionRunner:
    behaviours = {"navigation": behaviour, "push": behaviour}
    return MissionRunner(
        store, Dispatcher(store, planner, behaviours, DispatcherConfig(max_replans=max_replans))
    )


def test_plan_found_and_run_for_a_two_waypoint_navigation_goal(
    store: KnowledgeBase, planner: Planner
) -> None:
    seen: list[dict[str, object]] = []

    def navigate(blackboard: Blackboard) -> str:
        seen.append({key: blackboard[key] for key in ("origin", "destination", PLAN_STEP_KEY)})
        return SUCCEED

    result = runner(store, planner, navigate).run(goal("b"))
    assert result.status is MissionStatus.SUCCEEDED, result.reason
    assert result.executed == (PlanStep("navigation", ("a", "b"), 0.0, 10.0),)
    assert seen[0]["origin"] == "a" and seen[0]["destination"] == "b"
    assert seen[0][PLAN_STEP_KEY] == result.executed[0]
    assert robot_at(store) == ["b"]
    fact = store.propositions.get(("robot_at", ("b",), False))
    assert fact is not None and fact.provenance is Provenance.DECLARED  # waypoints: not anchored
    assert store.propositions.get(("robot_at", ("b",), True)) is None  # the goal was withdrawn


def test_goals_already_met_succeed_without_planning(store: KnowledgeBase, planner: Planner) -> None:
    result = runner(store, planner, succeed).run(goal("a"))
    assert result.status is MissionStatus.SUCCEEDED and result.plans == ()


def test_unreachable_goal_fails_with_a_clear_reason(store: KnowledgeBase, planner: Planner) -> None:
    store.objects.save(PddlObject("island", "wp"))
    result = runner(store, planner, succeed).run(goal("island"))
    assert result.status is MissionStatus.FAILED
    assert "no plan reaches robot_at(island)" in result.reason and "navigation" in result.reason
    assert robot_at(store) == ["a"]


def test_a_goal_whose_object_leaves_the_knowledge_base_mid_mission_fails_with_that_reason(
    store: KnowledgeBase, planner: Planner
) -> None:
    # An anchor merged into another (or forgotten) takes its object out while a mission aims at it.
    store.actions.save(push())
    store.objects.save(PddlObject("book_8", "item"))
    store.propositions.save(Proposition("object_at", ("book_8", "a"), provenance=Provenance.PERCEIVED))

    def push_and_lose_it(blackboard: Blackboard) -> str:
        store.objects.delete("book_8")
        return ABORT

    mission = Mission((Proposition("object_at", ("book_8", "b")),), name="fetch")
    result = runner(store, planner, push_and_lose_it).run(mission)
    assert result.status is MissionStatus.FAILED
    assert "book_8, which the knowledge base no longer holds" in result.reason


def test_a_problem_the_reader_refuses_is_a_failed_plan_not_a_crash(planner: Planner) -> None:
    from merlin2_sailor_behaviors.planning import PlanningStatus
    from merlin2_sailor_behaviors.planning.task import PlanningTask

    task = PlanningTask("(define (domain d) (:requirements :strips))",
                        "(define (problem p) (:domain d) (:goal (robot_at ghost)))", ())
    result = planner.plan(task)
    assert result.status is PlanningStatus.FAILED and "could not be read" in result.reason


def test_at_end_effects_are_not_applied_when_the_action_aborts(
    store: KnowledgeBase, planner: Planner
) -> None:
    calls: list[str] = []

    def abort(blackboard: Blackboard) -> str:
        calls.append(str(blackboard[PLAN_STEP_KEY]))
        assert robot_at(store) == []  # the at-start effect was applied while it ran
        blackboard["reason"] = "the door is shut"
        return ABORT

    result = runner(store, planner, abort, max_replans=0).run(goal("b"))
    assert result.status is MissionStatus.FAILED
    assert "gave up after 0 replan(s)" in result.reason and "aborted: the door is shut" in result.reason
    assert calls == ["navigation(a, b)"]
    assert robot_at(store) == ["a"]  # no robot_at(b); the at-start deletion was undone


def test_gives_up_after_the_configured_number_of_replans(
    store: KnowledgeBase, planner: Planner
) -> None:
    result = runner(store, planner, lambda blackboard: ABORT, max_replans=2).run(goal("d"))
    assert result.status is MissionStatus.FAILED and result.replans == 2
    assert "gave up after 2 replan(s)" in result.reason


def test_replans_after_an_abort_and_succeeds_by_another_route(
    store: KnowledgeBase, planner: Planner
) -> None:
    blocked: list[tuple[str, str]] = []

    def navigate(blackboard: Blackboard) -> str:
        corridor = (blackboard["origin"], blackboard["destination"])
        if not blocked:  # the first corridor tried turns out to be blocked
            blocked.append(corridor)
            store.propositions.delete(Proposition("connected", corridor))
            return ABORT
        return SUCCEED

    result = runner(store, planner, navigate).run(goal("d"))
    assert result.status is MissionStatus.SUCCEEDED, result.reason
    assert result.replans == 1
    assert all((s.objects[0], s.objects[1]) != blocked[0] for s in result.executed)
    assert result.executed[-1].objects[1] == "d" and robot_at(store) == ["d"]


def test_replans_when_a_fact_the_plan_relies_on_is_retracted_mid_plan(
    store: KnowledgeBase, planner: Planner
) -> None:
    retracted: list[tuple[str, str]] = []

    def navigate(blackboard: Blackboard) -> str:
        if not retracted:
            # Perception, in another thread, finds the corridor the next step needs blocked.
            corridor = (blackboard["destination"], "d")
            retracted.append(corridor)
            perception = threading.Thread(
                target=store.propositions.delete, args=(Proposition("connected", corridor),)
            )
            perception.start()
            perception.join(WAIT_SECONDS)
        return SUCCEED

    result = runner(store, planner, navigate).run(goal("d"))
    assert result.status is MissionStatus.SUCCEEDED, result.reason
    assert result.replans == 1
    first_plan_second_step = result.plans[0].steps[1]
    assert first_plan_second_step.objects == retracted[0]
    assert retracted[0] not in [step.objects for step in result.executed]
    assert robot_at(store) == ["d"]


def test_a_machine_cancelled_between_its_states_by_a_retraction_replans_the_mission(
    store: KnowledgeBase, planner: Planner
) -> None:
    # The corridor is needed over the whole drive, so retracting it cancels the running machine;
    # the cancel lands between its two states, where YASMIN 3.2 (and the local subset) raise.
    store.actions.save(dataclasses.replace(navigation(), conditions=(
        Condition("robot_at", ("origin",), "at start"),
        Condition("connected", ("origin", "destination"), "over all"),
    )))
    blocked: list[tuple[str, str]] = []

    def drive(blackboard: Blackboard) -> str:
        if not blocked:
            corridor = (blackboard["origin"], blackboard["destination"])
            blocked.append(corridor)
            perception = threading.Thread(target=store.propositions.delete,
                                          args=(Proposition("connected", corridor),))
            perception.start()
            perception.join(WAIT_SECONDS)
        return SUCCEED

    machine = StateMachine([SUCCEED, ABORT, CANCEL])
    machine.add_state("DRIVE", CbState([SUCCEED], drive), {SUCCEED: "ARRIVE"})
    machine.add_state("ARRIVE", CbState([SUCCEED], succeed))
    result = runner(store, planner, machine).run(goal("d"))
    assert result.status is MissionStatus.SUCCEEDED, result.reason
    assert result.replans == 1 and blocked
    assert blocked[0] not in [step.objects for step in result.executed]
    assert robot_at(store) == ["d"]


def test_retracting_a_fact_the_plan_does_not_need_changes_nothing(
    store: KnowledgeBase, planner: Planner
) -> None:
    def navigate(blackboard: Blackboard) -> str:
        store.propositions.delete(Proposition("connected", ("c", "b")))  # not on any a -> b plan
        return SUCCEED

    result = runner(store, planner, navigate).run(goal("b"))
    assert result.status is MissionStatus.SUCCEEDED and result.replans == 0


def test_mission_keeps_anchored_objects_and_expects_effects_on_them(
    store: KnowledgeBase, planner: Planner
) -> None:
    store.actions.save(push())
    for name in ("cup_1", "mug_2"):
        store.objects.save(PddlObject(name, "item"))
        store.propositions.save(
            Proposition("object_at", (name, "a"), provenance=Provenance.PERCEIVED)
        )
    mission = Mission((Proposition("object_at", ("cup_1", "b")),), name="tidy")
    result = runner(store, planner, succeed).run(mission)
    assert result.status is MissionStatus.SUCCEEDED, result.reason
    assert {o.name for o in store.objects.get_all()} >= {"cup_1", "mug_2", *WAYPOINTS}
    mug = store.propositions.get(("object_at", ("mug_2", "a"), False))
    assert mug is not None and mug.provenance is Provenance.PERCEIVED
    cup = store.propositions.get(("object_at", ("cup_1", "b"), False))
    assert cup is not None and cup.provenance is Provenance.EXPECTED  # for Track to confirm
    assert not [p for p in store.propositions.get_all() if p.is_goal]


def test_cancelling_a_mission_cancels_the_running_state_machine(
    store: KnowledgeBase, planner: Planner
) -> None:
    waiting = WaitForCancel()
    machine = StateMachine([SUCCEED, ABORT])
    machine.add_state("drive", waiting)
    mission_runner = runner(store, planner, machine)
    results = []
    thread = threading.Thread(target=lambda: results.append(mission_runner.run(goal("b"))))
    thread.start()
    assert waiting.started.wait(WAIT_SECONDS)
    mission_runner.cancel()
    thread.join(WAIT_SECONDS)
    assert results and results[0].status is MissionStatus.CANCELED
    assert robot_at(store) == ["a"]  # nothing of the cancelled navigation stays


def test_a_behaviour_returning_an_unknown_outcome_fails_the_mission_clearly(
    store: KnowledgeBase, planner: Planner
) -> None:
    result = runner(store, planner, lambda blackboard: "done").run(goal("b"))
    assert result.status is MissionStatus.FAILED and "returned 'done'" in result.reason
    assert robot_at(store) == ["a"]
