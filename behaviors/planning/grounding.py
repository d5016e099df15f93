"""An action's conditions and effects with the plan step's objects substituted.

Instantaneous actions have untimed literals; the dispatcher treats their conditions as "at
start" (checked before running) and their effects as "at end" (applied only on success), which
is what running a behaviour between checking and applying means.
"""

from dataclasses import dataclass

from merlin2_sailor.errors import KnowledgeError
from merlin2_sailor.knowledge import PddlAction, Timing
from merlin2_sailor.knowledge.model import TimedLiteral
from merlin2_sailor_behaviors.planning.facts import FactKey
from merlin2_sailor_behaviors.planning.plan import PlanStep


@dataclass(frozen=True)
class GroundLiteral:
    """A fact an action requires or changes; ``negative`` for "must be false" / "deletes"."""

    fact: FactKey
    negative: bool = False


@dataclass(frozen=True)
class GroundStep:
    """A plan step with its action's literals bound to the step's objects, grouped by time."""

    step: PlanStep
    parameters: dict[str, str]
    start_conditions: tuple[GroundLiteral, ...] = ()
    over_all_conditions: tuple[GroundLiteral, ...] = ()
    end_conditions: tuple[GroundLiteral, ...] = ()
    start_effects: tuple[GroundLiteral, ...] = ()
    end_effects: tuple[GroundLiteral, ...] = ()

    def positive_conditions(self) -> list[FactKey]:
        """Every fact the step needs true at some time while it runs."""
        literals = (*self.start_conditions, *self.over_all_conditions, *self.end_conditions)
        return [literal.fact for literal in literals if not literal.negative]


def ground_step(action: PddlAction, step: PlanStep) -> GroundStep:
    """Bind ``action``'s parameters to ``step``'s objects, in order.

    Raises:
        KnowledgeError: the step names a different number of objects than the action has
            parameters (the plan was made against another version of the action).
    """
    if len(action.parameters) != len(step.objects):
        raise KnowledgeError(
            f"plan step {step} gives {len(step.objects)} object(s) but action {action.name!r} "
            f"has {len(action.parameters)} parameter(s); replan against the current actions"
        )
    parameters = {p.name: name for p, name in zip(action.parameters, step.objects, strict=True)}

    def bind(literals: tuple[TimedLiteral, ...], times: tuple[Timing | None, ...]) -> tuple:
        return tuple(
            GroundLiteral(
                (literal.predicate, tuple(parameters[a] for a in literal.arguments)),
                literal.is_negative,
            )
            for literal in literals
            if literal.time in times
        )

    return GroundStep(
        step=step,
        parameters=parameters,
        start_conditions=bind(action.conditions, (Timing.AT_START, None)),
        over_all_conditions=bind(action.conditions, (Timing.OVER_ALL,)),
        end_conditions=bind(action.conditions, (Timing.AT_END,)),
        start_effects=bind(action.effects, (Timing.AT_START,)),
        end_effects=bind(action.effects, (Timing.AT_END, None)),
    )
