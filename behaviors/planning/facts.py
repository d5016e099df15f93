"""Facts as the mission runtime compares them: a predicate and its objects, nothing else.

A stored :class:`~merlin2_sailor.knowledge.Proposition` also carries whether it is a goal and
its provenance; for "does the plan's condition hold" and "was the fact the plan relied on
retracted" only predicate and objects matter, so the runtime works on :data:`FactKey` tuples.
"""

from collections.abc import Iterable

from merlin2_sailor.knowledge import KnowledgeBase, Proposition

FactKey = tuple[str, tuple[str, ...]]
"""A ground atom: predicate name and object names."""


def fact_key(proposition: Proposition) -> FactKey:
    """The atom of a proposition, whether fact or goal."""
    return (proposition.predicate, proposition.objects)


def holds(store: KnowledgeBase, fact: FactKey) -> bool:
    """Whether the knowledge base holds the fact (as a fact, not a goal)."""
    return store.propositions.get((fact[0], fact[1], False)) is not None


def unmet(store: KnowledgeBase, facts: Iterable[FactKey]) -> list[FactKey]:
    """The facts the knowledge base does not hold, in the order given."""
    return [fact for fact in facts if not holds(store, fact)]


def describe(fact: FactKey) -> str:
    """``robot_at(kitchen)``: how a fact appears in reasons and logs."""
    return f"{fact[0]}({', '.join(fact[1])})"
