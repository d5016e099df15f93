"""Where the knowledge base says the robot is: the ``robot_at`` facts, read and written.

The dispatcher moves ``robot_at`` through the actions' effects. Two writers know better and write
it themselves, DECLARED: find_object, which ends wherever it found the object, and the behaviors
node at start, which tells a fresh knowledge base where the robot stands so a mission can plan.
"""

from __future__ import annotations

from merlin2_sailor.knowledge import Change, KnowledgeBase, Proposition, Provenance
from merlin2_sailor_behaviors.actions.domain import OBJECT_AT, ROBOT_AT


def robot_locations(store: KnowledgeBase) -> tuple[str, ...]:
    """The places of every ``robot_at`` fact (normally one, none on a fresh knowledge base)."""
    return tuple(
        sorted(
            fact.objects[0]
            for fact in store.propositions.get_all()
            if fact.predicate == ROBOT_AT and not fact.is_goal and fact.objects
        )
    )


def declare_robot_at(store: KnowledgeBase, place: str) -> None:
    """Make ``robot_at(place)`` the one ``robot_at`` fact, in one batch: the robot is in one place."""
    stale = [
        fact
        for fact in store.propositions.get_all()
        if fact.predicate == ROBOT_AT and not fact.is_goal and fact.objects != (place,)
    ]
    changes = [Change.delete(fact) for fact in stale]
    if store.propositions.get((ROBOT_AT, (place,), False)) is None:
        changes.append(Change.save(Proposition(ROBOT_AT, (place,), provenance=Provenance.DECLARED)))
    if changes:
        store.apply(changes)


def objects_at(store: KnowledgeBase, place: str) -> tuple[str, ...]:
    """The objects the knowledge base places at ``place`` (``object_at(?o, place)`` facts)."""
    return tuple(
        sorted(
            {
                fact.objects[0]
                for fact in store.propositions_about(place)
                if fact.predicate == OBJECT_AT
                and not fact.is_goal
                and len(fact.objects) == 2
                and fact.objects[1] == place
            }
        )
    )
