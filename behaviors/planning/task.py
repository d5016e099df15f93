"""The PDDL domain and problem a mission plans over, generated from the knowledge base.

Why PDDL text rather than building unified-planning objects from the model directly: the
project already has one tested writer of PDDL (:mod:`merlin2_sailor.knowledge.pddl_writer`), and
it is what MERLIN2's own planners consume. Going through it means the runtime plans over exactly
the domain a MERLIN2 deployment would see, the text can be logged and replayed with any PDDL
planner when a plan surprises someone, and no second translation of the model to planning
semantics has to be kept in step with the first. Parsing costs milliseconds per plan.
"""

from collections.abc import Collection, Iterable
from dataclasses import dataclass, replace

from merlin2_sailor.knowledge import (
    KnowledgeBase,
    Proposition,
    domain_text,
    problem_text,
)
from merlin2_sailor.knowledge.model import ROOT_TYPE

DOMAIN_NAME = "merlin2"
PROBLEM_NAME = "sailor_mission"


@dataclass(frozen=True)
class PlanningTask:
    """A domain and a problem, as PDDL text, plus the action names the domain offers."""

    domain: str
    problem: str
    actions: tuple[str, ...]


def task_from_store(
    store: KnowledgeBase,
    goals: Iterable[Proposition],
    runnable_actions: Collection[str] | None = None,
) -> PlanningTask:
    """The task of reaching ``goals`` from the facts the knowledge base holds now.

    Only ``goals`` are planned for, not every goal stored in the knowledge base: another
    mission's leftover goals must not change this mission's plan. ``runnable_actions`` keeps the
    domain to the actions something can carry out (those with a behaviour), so the planner never
    chooses an action nobody runs; None keeps every stored action.
    """
    actions = [
        action
        for action in store.actions.get_all()
        if runnable_actions is None or action.name in runnable_actions
    ]
    goal_propositions = [replace(goal, is_goal=True) for goal in goals]
    # Only predicates the actions or goals mention: others cannot matter to the plan, and
    # Tamer 1.1.6 fails on a declared predicate that nothing mentions and nothing makes true.
    mentioned = {goal.predicate for goal in goal_propositions} | {
        literal.predicate for action in actions for literal in (*action.conditions, *action.effects)
    }
    # The anchoring node writes while a mission reads: a type before its objects, an object before
    # its facts. Read in the reverse order (facts, objects, types), so that what one read names was
    # written before the next read; and leave out what a concurrent removal left dangling, since
    # the next plan reads again. (Read types first, a cup seen a moment later was an object of an
    # undeclared type, and the planner's parser failed on it.)
    facts = [
        proposition
        for proposition in store.propositions.get_all()
        if not proposition.is_goal and proposition.predicate in mentioned
    ]
    predicates = [p for p in store.predicates.get_all() if p.name in mentioned]
    objects = store.objects.get_all()
    types = store.types.get_all()
    declared = {pddl_type.name for pddl_type in types} | {ROOT_TYPE}
    objects = [pddl_object for pddl_object in objects if pddl_object.type in declared]
    known = {pddl_object.name for pddl_object in objects}
    facts = [fact for fact in facts if known.issuperset(fact.objects)]
    return PlanningTask(
        domain=domain_text(DOMAIN_NAME, types, predicates, actions),
        problem=problem_text(PROBLEM_NAME, DOMAIN_NAME, objects, facts + goal_propositions),
        actions=tuple(sorted(action.name for action in actions)),
    )
