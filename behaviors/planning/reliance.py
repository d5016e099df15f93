"""Which facts of the knowledge base the rest of a plan relies on.

A fact is relied on when a remaining step needs it (or a goal is it) and no earlier remaining
step produces it: the plan takes it from the current state. If perception retracts such a fact,
the plan no longer works and the mission must replan; retracting any other fact does not matter
to this plan, so the runtime does not replan on every change in a busy knowledge base.
"""

from collections.abc import Iterable, Sequence

from merlin2_sailor_behaviors.planning.facts import FactKey
from merlin2_sailor_behaviors.planning.grounding import GroundLiteral, GroundStep


def relied_on_facts(
    steps: Sequence[GroundStep], goals: Iterable[FactKey], first_step_started: bool = False
) -> frozenset[FactKey]:
    """The facts ``steps`` (then ``goals``) take from the current state.

    With ``first_step_started`` the first step's at-start conditions are already consumed and
    its at-start effects already in the state.
    """
    produced: set[FactKey] = set()
    removed: set[FactKey] = set()
    relied: set[FactKey] = set()

    def need(conditions: Iterable[GroundLiteral]) -> None:
        for condition in conditions:
            if not condition.negative and condition.fact not in produced | removed:
                relied.add(condition.fact)

    def change(effects: Iterable[GroundLiteral]) -> None:
        for effect in effects:
            if effect.negative:
                produced.discard(effect.fact)
                removed.add(effect.fact)
            else:
                produced.add(effect.fact)
                removed.discard(effect.fact)

    for index, step in enumerate(steps):
        if not (first_step_started and index == 0):
            need(step.start_conditions)
            change(step.start_effects)
        need(step.over_all_conditions)
        need(step.end_conditions)
        change(step.end_effects)
    need(GroundLiteral(goal) for goal in goals)
    return frozenset(relied)
