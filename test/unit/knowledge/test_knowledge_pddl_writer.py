"""The PDDL writer's text is deterministic, complete and parses back with a real PDDL reader."""

import random

import pytest

from merlin2_sailor.errors import KnowledgeError
from merlin2_sailor.knowledge import (
    Change,
    Condition,
    Effect,
    Parameter,
    PddlAction,
    PddlObject,
    PddlType,
    Predicate,
    domain_from_store,
    domain_text,
    open_store,
    problem_from_store,
    problem_text,
    to_identifier,
)


def filled_store(items):
    store = open_store()
    store.apply([Change.save(item) for item in items])
    return store


def test_domain_text(scene):
    text = domain_from_store(filled_store(scene))
    assert text == (
        "(define (domain merlin2)\n"
        "  (:requirements :typing :durative-actions)\n"
        "  (:types\n"
        "    container robot wp - object\n"
        "    cup - container\n"
        "  )\n"
        "  (:predicates\n"
        "    (filled ?argument1 - container)\n"
        "    (object_at ?argument1 - object ?argument2 - wp)\n"
        "    (robot_at ?argument1 - robot ?argument2 - wp)\n"
        "  )\n"
        "  (:durative-action navigation\n"
        "    :parameters (?r - robot ?origin - wp ?to - wp)\n"
        "    :duration (= ?duration 10.0)\n"
        "    :condition (and\n"
        "      (at start (robot_at ?r ?origin))\n"
        "    )\n"
        "    :effect (and\n"
        "      (at start (not (robot_at ?r ?origin)))\n"
        "      (at end (robot_at ?r ?to))\n"
        "    )\n"
        "  )\n"
        ")\n"
    )


def test_problem_text(scene):
    text = problem_from_store(filled_store(scene), name="fetch", domain_name="merlin2")
    assert text == (
        "(define (problem fetch)\n"
        "  (:domain merlin2)\n"
        "  (:objects\n"
        "    cup_1 - cup\n"
        "    rb1 - robot\n"
        "    kitchen living_room - wp\n"
        "  )\n"
        "  (:init\n"
        "    (object_at cup_1 kitchen)\n"
        "    (robot_at rb1 kitchen)\n"
        "  )\n"
        "  (:goal (and\n"
        "    (robot_at rb1 living_room)\n"
        "  ))\n"
        ")\n"
    )


def test_output_does_not_depend_on_insertion_order(scene):
    shuffled = list(scene)
    random.Random(7).shuffle(shuffled)
    first, second = filled_store(scene), filled_store(shuffled)
    assert domain_from_store(first) == domain_from_store(second)
    assert problem_from_store(first) == problem_from_store(second)


def test_instantaneous_actions_and_negative_preconditions():
    action = PddlAction(
        "pick",
        parameters=(Parameter("thing", "cup"),),
        conditions=(Condition("holding", ("thing",), is_negative=True),),
        effects=(Effect("holding", ("thing",)),),
        durative=False,
    )
    text = domain_text("kitchen", [PddlType("cup")], [Predicate("holding", ("cup",))], [action])
    assert "(:requirements :typing :negative-preconditions)" in text
    assert "  (:action pick\n    :parameters (?thing - cup)\n" in text
    assert ":precondition (and\n      (not (holding ?thing))\n    )" in text


def test_hostile_class_names_stay_single_tokens():
    hostile = ") (:goal (and))\n; (robot_at rb1 kitchen)"
    type_name = to_identifier(hostile)
    text = problem_text("p", "d", [PddlObject("thing_1", type_name)], [])
    plain = problem_text("p", "d", [PddlObject("thing_1", "plain")], [])
    assert text == plain.replace("plain", type_name)


def test_names_of_domain_and_problem_are_validated():
    with pytest.raises(KnowledgeError, match="domain name"):
        domain_text("my domain", [], [], [])
    with pytest.raises(KnowledgeError, match="problem name"):
        problem_text("(evil)", "d", [], [])


def test_a_real_reader_parses_the_text_back(scene, tmp_path):
    pddl = pytest.importorskip("unified_planning.io")
    store = filled_store(scene)
    store.actions.save(
        PddlAction(
            "fill",
            parameters=(Parameter("thing", "container"),),
            conditions=(Condition("filled", ("thing",), is_negative=True),),
            effects=(Effect("filled", ("thing",)),),
            durative=False,
        )
    )
    domain_file, problem_file = tmp_path / "domain.pddl", tmp_path / "problem.pddl"
    domain_file.write_text(domain_from_store(store))
    problem_file.write_text(problem_from_store(store))
    problem = pddl.PDDLReader().parse_problem(str(domain_file), str(problem_file))
    assert {action.name for action in problem.actions} == {"navigation", "fill"}
    assert {obj.name for obj in problem.all_objects} == {"cup_1", "rb1", "kitchen", "living_room"}
    assert [str(goal) for goal in problem.goals] == ["robot_at(rb1, living_room)"]
    cup = problem.user_type("cup")
    assert cup.father == problem.user_type("container")
    initial = {
        str(fluent) for fluent, value in problem.explicit_initial_values.items() if value.is_true()
    }
    assert initial == {"object_at(cup_1, kitchen)", "robot_at(rb1, kitchen)"}
