"""A MERLIN2-style action: a PDDL action plus the state machine that carries it out.

MERLIN2 pairs each planning operator with a behaviour; here the pair is data. A
:class:`SailorAction` holds the :class:`~merlin2_sailor.knowledge.PddlAction`, the types and
predicates it mentions, and a factory that builds its state machine from a
:class:`~merlin2_sailor_behaviors.actions.context.BehaviorContext`. Whoever serves the action (the
``behaviors`` node, a MERLIN2 adapter, an in-process dispatcher) registers it in the knowledge
base when it starts, runs the machine with the plan step's objects on the blackboard under the
parameter names, and withdraws the action when it stops.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from merlin2_sailor.errors import KnowledgeError
from merlin2_sailor.knowledge import Change, KnowledgeBase, PddlAction, PddlType, Predicate
from merlin2_sailor.knowledge.model import ROOT_TYPE
from merlin2_sailor_behaviors.actions.context import BehaviorContext
from merlin2_sailor_behaviors.actions.keys import PLAN_STEP_KEY
from merlin2_sailor_behaviors.planning.plan import PlanStep
from merlin2_sailor_behaviors.state_machines import Blackboard, State

StateMachineFactory = Callable[[BehaviorContext], State]
"""Builds a fresh state machine (outcomes succeeded / aborted / canceled) for one action."""


@dataclass(frozen=True)
class SailorAction:
    """A PDDL action, what it needs declared, and how to build the machine that runs it."""

    pddl: PddlAction
    types: tuple[PddlType, ...]
    predicates: tuple[Predicate, ...]
    make_state_machine: StateMachineFactory

    def __post_init__(self) -> None:
        declared = {predicate.name for predicate in self.predicates}
        used = {literal.predicate for literal in (*self.pddl.conditions, *self.pddl.effects)}
        if used - declared:
            raise KnowledgeError(
                f"action {self.name!r} uses predicate(s) {sorted(used - declared)} it does not declare"
            )
        known_types = {ROOT_TYPE} | {pddl_type.name for pddl_type in self.types}
        needed = {parameter.type for parameter in self.pddl.parameters}
        needed |= {name for predicate in self.predicates for name in predicate.parameter_types}
        if needed - known_types:
            raise KnowledgeError(
                f"action {self.name!r} needs type(s) {sorted(needed - known_types)} it does not declare"
            )

    @property
    def name(self) -> str:
        return self.pddl.name

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return tuple(parameter.name for parameter in self.pddl.parameters)

    # Knowledge base.

    def register(self, store: KnowledgeBase) -> None:
        """Declare the action, with the types and predicates it needs, in one batch.

        Types and predicates already in the store are left as they are (the grounding declares
        ``object_at`` and ``wp`` too, and may know their hierarchy better); the action itself is
        saved, so a changed definition replaces the old one.

        Raises:
            KnowledgeError: the store refused the batch or cannot be reached.
        """
        changes = [Change.save(t) for t in self.types if store.types.get(t.name) is None]
        changes += [Change.save(p) for p in self.predicates if store.predicates.get(p.name) is None]
        changes.append(Change.save(self.pddl))
        store.apply(changes)

    def unregister(self, store: KnowledgeBase) -> bool:
        """Withdraw the action if the store still holds this definition; True when it did.

        The types and predicates stay: facts and other actions use them.
        """
        if store.actions.get(self.name) != self.pddl:
            return False
        store.apply([Change.delete(self.pddl)])
        return True

    # Running.

    def blackboard_for(self, objects: Sequence[str]) -> Blackboard:
        """A blackboard as the dispatcher fills it: each parameter's object, and the plan step.

        Raises:
            KnowledgeError: ``objects`` does not have one object per parameter.
        """
        objects = tuple(objects)
        if len(objects) != len(self.pddl.parameters):
            raise KnowledgeError(
                f"action {self.name!r} takes {len(self.pddl.parameters)} object(s) "
                f"({', '.join(self.parameter_names)}), got {len(objects)}: {list(objects)}"
            )
        blackboard = Blackboard()
        for parameter, name in zip(self.parameter_names, objects, strict=True):
            blackboard[parameter] = name
        blackboard[PLAN_STEP_KEY] = PlanStep(self.name, objects)
        return blackboard
