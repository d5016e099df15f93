"""The action base: SAILOR's domain registers in a knowledge base, plans with Aries, and runs."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from dataclasses import replace

import pytest

from merlin2_sailor.errors import ConfigurationError, KnowledgeError
from merlin2_sailor.knowledge import (
    KnowledgeBase,
    PddlObject,
    PddlType,
    Predicate,
    Proposition,
    open_store,
)
from merlin2_sailor_behaviors.actions import PLAN_STEP_KEY, SailorAction, active_state_path
from merlin2_sailor_behaviors.actions.domain import ACTIONS, PREDICATES
from merlin2_sailor_behaviors.catalogue import SAILOR_ACTIONS, select_actions
from merlin2_sailor_behaviors.planning import PlanStep
from merlin2_sailor_behaviors.state_machines import CANCEL, SUCCEED, CbState, StateMachine

from .waiting_state import WaitForCancel


@pytest.fixture
def store() -> Iterator[KnowledgeBase]:
    with open_store("memory") as knowledge:
        yield knowledge


def test_the_catalogue_serves_the_whole_domain_under_its_pddl_names() -> None:
    assert list(SAILOR_ACTIONS) == ["navigation", "explore", "approach_object", "find_object", "bring"]
    assert {name: action.pddl for name, action in SAILOR_ACTIONS.items()} == dict(ACTIONS)
    assert SAILOR_ACTIONS["navigation"].parameter_names == ("o", "d")  # MERLIN2's names
    assert [a.name for a in select_actions(["bring", "navigation"])] == ["bring", "navigation"]
    with pytest.raises(ConfigurationError, match="unknown action"):
        select_actions(["fly"])


def test_registering_declares_types_predicates_and_the_action_in_one_batch(store: KnowledgeBase) -> None:
    batches: list[int] = []
    store.subscribe(lambda events: batches.append(len(events)))
    SAILOR_ACTIONS["bring"].register(store)
    assert len(batches) == 1
    assert store.types.get("wp") == PddlType("wp")
    assert {p.name for p in store.predicates.get_all()} == {"robot_at", "object_at", "carried"}
    assert store.actions.get("bring") == ACTIONS["bring"]
    SAILOR_ACTIONS["bring"].register(store)  # again: nothing new
    assert len(batches) == 1


def test_registering_leaves_declarations_it_finds_alone(store: KnowledgeBase) -> None:
    store.types.save(PddlType("place"))
    store.types.save(PddlType("wp", "place"))  # the grounding knows a hierarchy
    for action in SAILOR_ACTIONS.values():
        action.register(store)
    assert store.types.get("wp") == PddlType("wp", "place")
    assert set(PREDICATES) <= {p.name for p in store.predicates.get_all()}


def test_unregistering_withdraws_only_its_own_definition(store: KnowledgeBase) -> None:
    navigation = SAILOR_ACTIONS["navigation"]
    navigation.register(store)
    assert navigation.unregister(store) and store.actions.get("navigation") is None
    assert store.predicates.get("robot_at") is not None  # facts may still use it
    navigation.register(store)
    other = replace(ACTIONS["navigation"], duration=30.0)
    store.actions.save(other)  # someone else's navigation now
    assert not navigation.unregister(store) and store.actions.get("navigation") == other


def test_an_action_must_declare_what_it_uses() -> None:
    with pytest.raises(KnowledgeError, match="robot_at"):
        SailorAction(ACTIONS["navigation"], (PddlType("wp"),), (), lambda context: CbState([SUCCEED], str))
    with pytest.raises(KnowledgeError, match="'wp'"):
        SailorAction(ACTIONS["navigation"], (), (Predicate("robot_at", ("wp",)),), lambda c: None)


def test_the_blackboard_holds_each_parameters_object_and_the_plan_step() -> None:
    blackboard = SAILOR_ACTIONS["bring"].blackboard_for(["cup_1", "a", "b"])
    assert (blackboard["target"], blackboard["origin"], blackboard["destination"]) == ("cup_1", "a", "b")
    assert blackboard[PLAN_STEP_KEY] == PlanStep("bring", ("cup_1", "a", "b"))
    with pytest.raises(KnowledgeError, match="takes 3 object"):
        SAILOR_ACTIONS["bring"].blackboard_for(["cup_1"])


def test_progress_names_the_running_state_through_nested_machines() -> None:
    inner = StateMachine([SUCCEED, CANCEL])
    waiting = WaitForCancel()
    inner.add_state("WAITING", waiting)
    outer = StateMachine([SUCCEED, CANCEL])
    outer.add_state("SEARCHING", inner)
    assert active_state_path(outer) == ""
    outcomes = []
    thread = threading.Thread(target=lambda: outcomes.append(outer()))
    thread.start()
    assert waiting.started.wait(5.0)
    assert active_state_path(outer) == "SEARCHING/WAITING"
    outer.cancel_state()
    thread.join(5.0)
    assert outcomes == [CANCEL]


# --- Planning with the registered domain -----------------------------------------------------

up_aries = pytest.importorskip("up_aries", reason="planning needs Aries: pip install up-aries")

from merlin2_sailor_behaviors.planning import Planner, task_from_store  # noqa: E402


@pytest.fixture(scope="module")
def planner() -> Planner:
    return Planner()


@pytest.fixture
def world(store: KnowledgeBase) -> KnowledgeBase:
    for action in SAILOR_ACTIONS.values():
        action.register(store)
    store.types.save(PddlType("cup"))
    for name in ("a", "b", "c"):
        store.objects.save(PddlObject(name, "wp"))
    store.objects.save(PddlObject("cup_1", "cup"))
    store.propositions.save(Proposition("robot_at", ("a",)))
    return store


FETCH_ACTIONS = ("navigation", "approach_object", "find_object")


def plan(store: KnowledgeBase, planner: Planner, *goals: Proposition, actions=FETCH_ACTIONS) -> list[str]:
    """Plan with the actions a mission would allow: Aries is a satisficing planner, and given
    every action it may return longer valid plans (carrying a cup around to get somewhere)."""
    result = planner.plan(task_from_store(store, goals, actions))
    assert result.plan is not None, result.reason
    return [str(step) for step in result.plan.steps]


def test_plans_a_navigation_between_waypoints(world: KnowledgeBase, planner: Planner) -> None:
    assert plan(world, planner, Proposition("robot_at", ("b",))) == ["navigation(a, b)"]


def test_plans_navigation_then_approach_to_an_object_anchored_elsewhere(
    world: KnowledgeBase, planner: Planner
) -> None:
    world.propositions.save(Proposition("object_at", ("cup_1", "b")))
    assert plan(world, planner, Proposition("robot_near", ("cup_1",))) == [
        "navigation(a, b)", "approach_object(cup_1, b)"]


def test_plans_a_find_for_a_missing_object(world: KnowledgeBase, planner: Planner) -> None:
    world.propositions.save(Proposition("missing", ("cup_1",)))
    steps = plan(world, planner, Proposition("robot_near", ("cup_1",)))
    # Any valid plan searches for it; a satisficing planner may drive somewhere first.
    assert steps[-1].startswith("find_object(cup_1, ") and all(s.startswith("navigation(") for s in steps[:-1])


def test_plans_bring_to_move_an_object(world: KnowledgeBase, planner: Planner) -> None:
    world.propositions.save(Proposition("object_at", ("cup_1", "b")))
    steps = plan(world, planner, Proposition("object_at", ("cup_1", "c")), actions=("navigation", "bring"))
    assert steps == ["navigation(a, b)", "bring(cup_1, b, c)"]
