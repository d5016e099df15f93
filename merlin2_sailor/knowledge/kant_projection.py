"""How SAILOR's typed knowledge fits into KANT, which has neither subtypes nor fractional durations.

KANT (MERLIN2's knowledge base, 1.1.0) keeps types flat and accepts a fact only when each
object's type *is* the type its predicate names: ``object_at(cup_1, kitchen)`` with
``cup_1 - cup`` is refused when the predicate is ``object_at(?o - object ?w - wp)``. SAILOR's
model has a type tree (``cup -> container -> object``) and checks facts by subtyping. Its actions'
durations are seconds as floats; KANT stores whole seconds.

The projection is the one place that decides what KANT receives:

* **Kinds.** Types that meet in a fact (an object's type and the predicate parameter it fills) or
  in an action (a parameter's type and the predicate parameter it fills) belong to one *kind*,
  named after the most general type among them (their common ancestor). In KANT, objects, predicate
  parameters and action parameters carry their kind, so every fact KANT is given type-checks
  there: with SAILOR's grounding, anchored objects (``cup_1 - cup``) are ``object`` in KANT, as
  MERLIN2's own ``object`` type expects, and waypoints stay ``wp``. Types that never meet stay
  themselves. Every SAILOR type is still declared in KANT by name, without its supertype.
* **Durations** go to KANT rounded up to whole seconds (at least one): an action never gets less
  time than it asked for.
* **What KANT cannot hold** (an object's own class once it is stored as its kind, supertypes,
  fractional durations, provenance) is remembered for the items this adapter wrote, so reading
  them back gives what was written. After a restart those items read back as KANT holds them
  (``cup_1 - object``) until SAILOR writes them again: that is the degradation, and the only one.
* ``object`` is a plain type in KANT (MERLIN2 declares it); in SAILOR it is PDDL's root and never
  declared, so a KANT type named ``object`` is not read back as a type.
"""

from __future__ import annotations

import math
from collections.abc import Hashable, Iterable, Mapping
from dataclasses import replace

from merlin2_sailor.knowledge.changes import ItemKind
from merlin2_sailor.knowledge.model import (
    ROOT_TYPE,
    KnowledgeItem,
    Parameter,
    PddlAction,
    PddlObject,
    PddlType,
    Predicate,
    Proposition,
)

ItemKey = tuple[ItemKind, Hashable]


def item_key(kind: ItemKind, item: KnowledgeItem) -> ItemKey:
    """The key a store files an item under (a proposition's :attr:`Proposition.key`)."""
    return (kind, item.key if isinstance(item, Proposition) else item.name)  # type: ignore[union-attr]


def kant_duration(seconds: float) -> int:
    """Whole seconds, rounded up, at least one: what KANT's integer duration can say."""
    return max(1, math.ceil(seconds - 1e-9))


class KantKinds:
    """The kind of every type, computed from a whole knowledge state (see the module docstring)."""

    def __init__(self, items: Iterable[KnowledgeItem]) -> None:
        items = list(items)
        self._supertypes = {item.name: item.supertype for item in items if isinstance(item, PddlType)}
        object_types = {item.name: item.type for item in items if isinstance(item, PddlObject)}
        predicates = {item.name: item.parameter_types for item in items if isinstance(item, Predicate)}
        self._parent: dict[str, str] = {}
        for item in items:
            if isinstance(item, Proposition):
                for name, parameter_type in zip(item.objects, predicates.get(item.predicate, ()), strict=False):
                    if name in object_types:
                        self._join(object_types[name], parameter_type)
            elif isinstance(item, PddlAction):
                for literal in (*item.conditions, *item.effects):
                    signature = predicates.get(literal.predicate, ())
                    for argument, parameter_type in zip(literal.arguments, signature, strict=False):
                        self._join(item.parameter_type(argument), parameter_type)
        groups: dict[str, set[str]] = {}
        for type_name in list(self._parent):
            groups.setdefault(self._find(type_name), set()).add(type_name)
        self._kind = {
            member: self._common_ancestor(members) for members in groups.values() for member in members
        }

    def __call__(self, type_name: str) -> str:
        """The type KANT stores in place of ``type_name``."""
        return self._kind.get(type_name, type_name)

    @property
    def mapping(self) -> Mapping[str, str]:
        """Every type whose kind is another type, to that kind."""
        return {name: kind for name, kind in self._kind.items() if name != kind}

    def _find(self, type_name: str) -> str:
        self._parent.setdefault(type_name, type_name)
        while self._parent[type_name] != type_name:
            self._parent[type_name] = self._parent[self._parent[type_name]]
            type_name = self._parent[type_name]
        return type_name

    def _join(self, first: str, second: str) -> None:
        self._parent[self._find(first)] = self._find(second)

    def _ancestry(self, type_name: str) -> list[str]:
        """``type_name`` and its supertypes up to the root, nearest first."""
        chain = [type_name]
        while chain[-1] != ROOT_TYPE and len(chain) <= len(self._supertypes) + 1:
            chain.append(self._supertypes.get(chain[-1], ROOT_TYPE))
        return chain

    def _common_ancestor(self, members: set[str]) -> str:
        chains = [self._ancestry(member) for member in sorted(members)]
        shared = set(chains[0]).intersection(*map(set, chains[1:]))
        return next(name for name in chains[0] if name in shared)


class KantProjection:
    """Turns SAILOR items into what KANT is given, and KANT's items back into what SAILOR wrote."""

    def __init__(self) -> None:
        self.kinds = KantKinds(())
        self._written: dict[ItemKey, KnowledgeItem] = {}

    def update(self, items: Iterable[KnowledgeItem]) -> None:
        """Recompute the kinds from the whole state SAILOR now holds (after a batch)."""
        self.kinds = KantKinds(items)

    def project(self, item: KnowledgeItem) -> KnowledgeItem | None:
        """What KANT holds for ``item``: None for the root type, which KANT must not be sent."""
        kind = self.kinds
        if isinstance(item, PddlType):
            return None if item.name == ROOT_TYPE else PddlType(item.name)
        if isinstance(item, PddlObject):
            return PddlObject(item.name, kind(item.type))
        if isinstance(item, Predicate):
            return Predicate(item.name, tuple(kind(t) for t in item.parameter_types))
        if isinstance(item, Proposition):
            return Proposition(item.predicate, item.objects, item.is_goal)
        parameters = tuple(Parameter(p.name, kind(p.type)) for p in item.parameters)
        duration = float(kant_duration(item.duration)) if item.durative else item.duration
        return replace(item, parameters=parameters, duration=duration)

    def remember(self, kind: ItemKind, item: KnowledgeItem) -> None:
        """``item`` was written to KANT: read it back as it is, not as KANT holds it."""
        self._written[item_key(kind, item)] = item

    def forget(self, kind: ItemKind, item: KnowledgeItem) -> None:
        self._written.pop(item_key(kind, item), None)

    def restore(self, kind: ItemKind, stored: KnowledgeItem) -> KnowledgeItem:
        """The item SAILOR wrote when KANT still holds its projection, else KANT's item as it is."""
        written = self._written.get(item_key(kind, stored))
        if written is not None and self.project(written) == self.project(stored):
            return written
        return stored
