"""Parts of the mission runtime that need no planning engine: task text, reliance, effects."""

from __future__ import annotations

import pytest

from merlin2_sailor.errors import DependencyError
from merlin2_sailor.knowledge import (
    Condition,
    Effect,
    Parameter,
    PddlAction,
    PddlObject,
    PddlType,
    Predicate,
    Proposition,
    Provenance,
    open_store,
)
from merlin2_sailor.knowledge.model import ROOT_TYPE
from merlin2_sailor_behaviors.planning import (
    EffectWriter,
    Planner,
    PlannerConfig,
    PlanStep,
    anchored_by_provenance,
    task_from_store,
)
from merlin2_sailor_behaviors.planning.grounding import GroundLiteral, ground_step
from merlin2_sailor_behaviors.planning.reliance import relied_on_facts

NAVIGATION = PddlAction(
    "navigation",
    (Parameter("origin", "wp"), Parameter("destination", "wp")),
    (Condition("robot_at", ("origin",), "at start"),),
    (
        Effect("robot_at", ("origin",), "at start", is_negative=True),
        Effect("robot_at", ("destination",), "at end"),
    ),
)


def test_grounding_binds_parameters_and_groups_literals_by_time() -> None:
    step = ground_step(NAVIGATION, PlanStep("navigation", ("a", "b")))
    assert step.parameters == {"origin": "a", "destination": "b"}
    assert step.start_conditions == (GroundLiteral(("robot_at", ("a",))),)
    assert step.start_effects == (GroundLiteral(("robot_at", ("a",)), negative=True),)
    assert step.end_effects == (GroundLiteral(("robot_at", ("b",))),)


def test_relied_on_facts_are_those_no_earlier_step_produces() -> None:
    steps = [
        ground_step(NAVIGATION, PlanStep("navigation", ("a", "b"))),
        ground_step(NAVIGATION, PlanStep("navigation", ("b", "c"))),
    ]
    goals = [("robot_at", ("c",)), ("door_open", ("d",))]
    assert relied_on_facts(steps, goals) == {("robot_at", ("a",)), ("door_open", ("d",))}
    # Once the first step has started, its start condition is consumed.
    assert relied_on_facts(steps, goals, first_step_started=True) == {("door_open", ("d",))}


def test_task_keeps_runnable_actions_and_only_the_missions_goals() -> None:
    with open_store("memory") as store:
        store.types.save(PddlType("wp"))
        store.objects.save(PddlObject("a", "wp"))
        store.predicates.save(Predicate("robot_at", ("wp",)))
        store.predicates.save(Predicate("unused", ()))
        store.actions.save(NAVIGATION)
        store.actions.save(PddlAction("dance", (), (), (Effect("unused", (), "at end"),)))
        store.propositions.save(Proposition("robot_at", ("a",), is_goal=True))  # someone else's
        task = task_from_store(store, [Proposition("robot_at", ("a",))], {"navigation"})
    assert task.actions == ("navigation",)
    assert "dance" not in task.domain and "unused" not in task.domain
    assert "(:goal (and\n    (robot_at a)\n  ))" in task.problem


def test_effects_on_anchored_objects_are_expected_and_others_declared() -> None:
    with open_store("memory") as store:
        store.types.save(PddlType("wp"))
        store.types.save(PddlType("item"))
        for name, type_name in (("a", "wp"), ("b", "wp"), ("cup_1", "item")):
            store.objects.save(PddlObject(name, type_name))
        store.predicates.save(Predicate("robot_at", ("wp",)))
        store.predicates.save(Predicate("object_at", ("item", "wp")))
        perceived = Proposition("object_at", ("cup_1", "a"), provenance=Provenance.PERCEIVED)
        store.propositions.save(perceived)
        writer = EffectWriter(store, anchored_by_provenance(store))
        applied = writer.apply(
            [
                GroundLiteral(("object_at", ("cup_1", "b"))),
                GroundLiteral(("robot_at", ("b",))),
                GroundLiteral(("object_at", ("cup_1", "a"))),  # held already: left as perceived
            ]
        )
        by_key = {p.key: p.provenance for p in store.propositions.get_all()}
        assert by_key[("object_at", ("cup_1", "b"), False)] is Provenance.EXPECTED
        assert by_key[("robot_at", ("b",), False)] is Provenance.DECLARED
        assert by_key[perceived.key] is Provenance.PERCEIVED
        writer.undo(applied)
        assert store.propositions.get_all() == (perceived,)


def test_a_missing_engine_is_a_dependency_error_naming_the_package() -> None:
    planner = Planner(PlannerConfig(engine="no_such_engine"))
    with pytest.raises(DependencyError, match="pip install its up-"):
        planner.plan(task_from_store(open_store("memory"), [Proposition("x")]))


class _WrittenWhileRead:
    """A store that the anchoring node writes to while the task is read: before each table read,
    the writer takes its next step."""

    def __init__(self, store, steps) -> None:
        self._store, self._steps = store, list(steps)

    def __getattr__(self, name):
        table = getattr(self._store, name)
        outer = self

        class Table:
            def get_all(self):
                if outer._steps:
                    outer._steps.pop(0)()
                return table.get_all()

            def __getattr__(self, attribute):
                return getattr(table, attribute)

        return Table()


def _anchor_cup(store) -> None:
    store.types.save(PddlType("cup"))
    store.objects.save(PddlObject("cup_1", "cup"))
    store.propositions.save(Proposition("object_at", ("cup_1", "a")))


def _forget_cup(store) -> None:
    store.propositions.delete(Proposition("object_at", ("cup_1", "a")))
    store.objects.delete(PddlObject("cup_1", "cup"))


@pytest.mark.parametrize("change", ["anchor", "forget"])
@pytest.mark.parametrize("before_read", range(6))
def test_a_task_read_while_the_anchoring_node_writes_is_consistent_and_parses(change: str, before_read: int) -> None:
    """A cup anchored while a mission reads the knowledge base: its type, object and fact land
    between the task's reads. Whatever the timing, every object's type is declared and every fact
    names declared objects (the demo crashed on "KeyError: 'cup'" when types were read first)."""
    from unified_planning.io import PDDLReader

    with open_store("memory") as store:
        store.types.save(PddlType("wp"))
        store.objects.save(PddlObject("a", "wp"))
        store.predicates.save(Predicate("robot_at", ("wp",)))
        store.predicates.save(Predicate("object_at", (ROOT_TYPE, "wp")))
        store.actions.save(NAVIGATION)
        store.actions.save(PddlAction("look", (Parameter("o", ROOT_TYPE), Parameter("w", "wp")),
                                      (Condition("object_at", ("o", "w"), "at start"),), ()))
        if change == "forget":
            _anchor_cup(store)
        write = _anchor_cup if change == "anchor" else _forget_cup
        writes = [lambda: None] * before_read + [lambda: write(store)]
        task = task_from_store(_WrittenWhileRead(store, writes), [Proposition("robot_at", ("a",))])
    problem = PDDLReader().parse_problem_string(task.domain, task.problem)
    names = {item.name for item in problem.all_objects}
    assert "a" in names
    if "(object_at cup_1 a)" in task.problem:
        assert "cup_1" in names
