"""MERLIN2's planner fed KANT's flat types rooted at ``object`` (merlin2_sailor_behaviors.merlin2.planner)."""

from __future__ import annotations

import pytest

from merlin2_sailor_behaviors.merlin2.planner import rooted_types

# The shape of MERLIN2's PDDL generator output over KANT: types flat, 'object' among them.
DOMAIN = """(define (domain merlin2)
(:requirements :typing :negative-preconditions :durative-actions)
(:types
\tbook
\tobject
\twp
)
(:predicates
\t(missing ?o0 - object)
\t(robot_at ?w0 - wp)
\t(robot_near ?o0 - object)
)
(:durative-action find_object
\t:parameters ( ?target - object ?origin - wp)
\t:duration (= ?duration 10)
\t:condition (and
\t\t(at start (robot_at ?origin))
\t\t(at start (missing ?target))
\t)
\t:effect (and
\t\t(at start (not (robot_at ?origin)))
\t\t(at end (robot_near ?target))
\t)
)
)
"""
PROBLEM = """(define (problem merlin2_prb)
(:domain merlin2)
(:objects
\tcup_1 - object
\tkitchen - wp
)
(:init
\t(missing cup_1)
\t(robot_at kitchen)
)
(:goal
\t(robot_near cup_1)
)
)
"""


def test_flat_types_become_subtypes_of_object_and_nothing_else_changes() -> None:
    rooted = rooted_types(DOMAIN)
    assert "(:types\n\tbook\n\twp - object\n)" in rooted
    assert rooted.replace("(:types\n\tbook\n\twp - object\n)", "") == DOMAIN.replace(
        "(:types\n\tbook\n\tobject\n\twp\n)", "")


@pytest.mark.parametrize("domain", [
    "(define (domain d) (:types cup wp - object) (:predicates (p ?x - cup)))",  # already rooted
    "(define (domain d) (:predicates (p)))",  # no types
    "(define (domain d) (:types object) (:predicates (p ?x - object)))",  # only the root
])
def test_domains_that_need_nothing_are_left_alone(domain: str) -> None:
    assert rooted_types(domain) == domain


def test_unified_planning_plans_the_rooted_domain(tmp_path) -> None:
    from unified_planning.io.pddl_reader import PDDLReader
    from unified_planning.shortcuts import OneshotPlanner

    (tmp_path / "domain.pddl").write_text(rooted_types(DOMAIN))
    (tmp_path / "problem.pddl").write_text(PROBLEM)
    problem = PDDLReader().parse_problem(str(tmp_path / "domain.pddl"), str(tmp_path / "problem.pddl"))
    with OneshotPlanner(problem_kind=problem.kind) as planner:  # as MERLIN2's UP planner chooses
        result = planner.solve(problem)
    steps = [str(item[1]) for item in result.plan.timed_actions]
    assert steps == ["find_object(cup_1, kitchen)"]
