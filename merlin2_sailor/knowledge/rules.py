"""The rules every store obeys, written once so memory, SQLite and MongoDB cannot disagree.

:class:`KnowledgeState` holds the items in memory and applies batches of changes to them:

* saving is save-or-update and idempotent: saving an equal item changes nothing and reports
  nothing;
* saving an item saves the types it names when they are unknown (KANT saves an object's type
  with the object), as children of ``object``;
* deleting an item deletes everything that refers to it: a type takes its subtypes, its objects
  and the predicates and actions typed with it; an object takes the propositions that use it; a
  predicate takes its propositions and the actions that use it;
* after a batch, every proposition and action it touched must type-check: the predicate exists,
  the arity matches and each argument's type is the expected type or one of its subtypes.
  Otherwise the whole batch is undone and a :class:`KnowledgeError` names the first problem.

Rules are checked at the end of a batch rather than change by change, so the order of changes
inside a batch does not matter (a proposition may come before its object) except where it must:
a later delete still cascades over what an earlier save added.
"""

from collections.abc import Hashable, Iterable
from dataclasses import dataclass, field
from itertools import chain
from typing import Any

from merlin2_sailor.errors import KnowledgeError
from merlin2_sailor.knowledge.changes import (
    Change,
    ChangeEvent,
    ItemKind,
    Operation,
    key_of,
    kind_of,
)
from merlin2_sailor.knowledge.model import (
    ROOT_TYPE,
    KnowledgeItem,
    PddlAction,
    PddlObject,
    PddlType,
    Predicate,
    Proposition,
    PropositionKey,
    TimedLiteral,
)

DELETE_ORDER = (
    ItemKind.PROPOSITION,
    ItemKind.ACTION,
    ItemKind.OBJECT,
    ItemKind.PREDICATE,
    ItemKind.TYPE,
)
"""Deletions are reported dependents first, so a listener replaying them sees no dangling item."""

SAVE_ORDER = tuple(reversed(DELETE_ORDER))
"""Saves are reported dependencies first, for the same reason."""

Originals = dict[tuple[ItemKind, Hashable], KnowledgeItem | None]
"""What each key a batch touched held before it, None for nothing."""


@dataclass
class _Batch:
    """What one batch has touched so far: enough to check it, report it and undo it."""

    originals: Originals = field(default_factory=dict)
    propositions_to_check: dict[PropositionKey, None] = field(default_factory=dict)
    actions_to_check: dict[str, None] = field(default_factory=dict)
    check_everything: bool = False


class Transaction:
    """A batch already applied to a state: the events it caused, and the way to take it back.

    Stores apply a batch to memory first, then write its events to their database; when the
    write fails they call :meth:`rollback` so memory and database never disagree.
    """

    def __init__(
        self,
        state: "KnowledgeState",
        originals: Originals,
        events: tuple[ChangeEvent, ...],
    ) -> None:
        self._state = state
        self._originals = originals
        self.events = events

    def rollback(self) -> None:
        """Restore every item the batch touched to what it was before."""
        self._state._restore(self._originals)


class KnowledgeState:
    """The items of a knowledge base in memory, changed only through :meth:`apply`."""

    def __init__(self) -> None:
        self._types: dict[str, PddlType] = {}
        self._objects: dict[str, PddlObject] = {}
        self._predicates: dict[str, Predicate] = {}
        self._propositions: dict[PropositionKey, Proposition] = {}
        self._actions: dict[str, PddlAction] = {}
        self._items: dict[ItemKind, dict[Any, Any]] = {
            ItemKind.TYPE: self._types,
            ItemKind.OBJECT: self._objects,
            ItemKind.PREDICATE: self._predicates,
            ItemKind.PROPOSITION: self._propositions,
            ItemKind.ACTION: self._actions,
        }
        # Forgetting an anchor deletes its object on the perception path, so finding the
        # propositions that use an object must not scan them all. Dicts keep insertion order.
        self._propositions_by_object: dict[str, dict[PropositionKey, None]] = {}

    # Reading.

    def get(self, kind: ItemKind, key: Hashable) -> KnowledgeItem | None:
        """The item stored under ``key``, or None."""
        return self._items[kind].get(key)

    def get_all(self, kind: ItemKind) -> tuple[KnowledgeItem, ...]:
        """Every item of a kind, in no guaranteed order."""
        return tuple(self._items[kind].values())

    def propositions_about(self, object_name: str) -> tuple[Proposition, ...]:
        """The propositions (facts and goals) that use an object."""
        keys = self._propositions_by_object.get(object_name, {})
        return tuple(self._propositions[key] for key in keys)

    def is_subtype(self, type_name: str, ancestor: str) -> bool:
        """Tell whether ``type_name`` is ``ancestor`` or derives from it."""
        while True:
            if type_name in (ancestor, ROOT_TYPE):
                return type_name == ancestor
            known = self._types.get(type_name)
            if known is None:
                return False
            type_name = known.supertype

    # Writing.

    def load(self, items: Iterable[KnowledgeItem]) -> None:
        """Fill an empty state from a database this package wrote, trusting its consistency."""
        for item in items:
            self._raw_put(kind_of(item), key_of(item), item)

    def apply(self, changes: Iterable[Change]) -> Transaction:
        """Apply a batch whole or not at all, and report its net effect as events."""
        batch = _Batch()
        try:
            for change in changes:
                if not isinstance(change, Change):
                    raise KnowledgeError(
                        f"{change!r} is not a Change; build one with Change.save(item) or "
                        "Change.delete(item)"
                    )
                if change.item is not None and change.operation is Operation.SAVE:
                    self._save(change.item, batch)
                else:
                    self._delete(change.kind, change.key, batch)
            self._check(batch)
        except BaseException:
            self._restore(batch.originals)
            raise
        return Transaction(self, batch.originals, self._net_events(batch.originals))

    # Saving.

    def _save(self, item: KnowledgeItem, batch: _Batch) -> None:
        kind = kind_of(item)
        existing = self._items[kind].get(key_of(item))
        if existing == item:
            return
        match item:
            case PddlType():
                self._ensure_type(item.supertype, batch)
                self._refuse_cycle(item)
                if existing is not None:
                    batch.check_everything = True
            case PddlObject():
                self._ensure_type(item.type, batch)
                if existing is not None:
                    batch.propositions_to_check.update(
                        self._propositions_by_object.get(item.name, {})
                    )
            case Predicate():
                for type_name in item.parameter_types:
                    self._ensure_type(type_name, batch)
                if existing is not None:
                    batch.propositions_to_check.update(
                        dict.fromkeys(
                            proposition.key for proposition in self._propositions_of(item.name)
                        )
                    )
                    batch.actions_to_check.update(
                        dict.fromkeys(action.name for action in self._actions_using(item.name))
                    )
            case Proposition():
                batch.propositions_to_check[item.key] = None
            case PddlAction():
                for parameter in item.parameters:
                    self._ensure_type(parameter.type, batch)
                batch.actions_to_check[item.name] = None
        self._put(kind, key_of(item), item, batch)

    def _ensure_type(self, type_name: str, batch: _Batch) -> None:
        if type_name != ROOT_TYPE and type_name not in self._types:
            self._put(ItemKind.TYPE, type_name, PddlType(type_name), batch)

    def _refuse_cycle(self, new_type: PddlType) -> None:
        if self.is_subtype(new_type.supertype, new_type.name):
            raise KnowledgeError(
                f"type {new_type.name!r} cannot derive from {new_type.supertype!r}, which "
                f"already derives from {new_type.name!r}; a type hierarchy must be a tree"
            )

    # Deleting.

    def _delete(self, kind: ItemKind, key: Hashable, batch: _Batch) -> None:
        item = self._items[kind].get(key)
        if item is None:
            if kind is ItemKind.TYPE and key == ROOT_TYPE:
                raise KnowledgeError(f"'{ROOT_TYPE}' is PDDL's built-in type and is never deleted")
            return
        match item:
            case PddlType():
                self._delete_dependents_of_type(item.name, batch)
            case PddlObject():
                for proposition_key in list(self._propositions_by_object.get(item.name, {})):
                    self._remove(ItemKind.PROPOSITION, proposition_key, batch)
            case Predicate():
                for proposition in self._propositions_of(item.name):
                    self._remove(ItemKind.PROPOSITION, proposition.key, batch)
                for action in self._actions_using(item.name):
                    self._remove(ItemKind.ACTION, action.name, batch)
        self._remove(kind, key, batch)

    def _delete_dependents_of_type(self, type_name: str, batch: _Batch) -> None:
        subtypes = [child.name for child in self._types.values() if child.supertype == type_name]
        objects = [thing.name for thing in self._objects.values() if thing.type == type_name]
        predicates = [
            predicate.name
            for predicate in self._predicates.values()
            if type_name in predicate.parameter_types
        ]
        actions = [
            action.name
            for action in self._actions.values()
            if any(parameter.type == type_name for parameter in action.parameters)
        ]
        for kind, names in (
            (ItemKind.TYPE, subtypes),
            (ItemKind.OBJECT, objects),
            (ItemKind.PREDICATE, predicates),
            (ItemKind.ACTION, actions),
        ):
            for name in names:
                self._delete(kind, name, batch)

    def _propositions_of(self, predicate_name: str) -> list[Proposition]:
        return [
            proposition
            for proposition in self._propositions.values()
            if proposition.predicate == predicate_name
        ]

    def _actions_using(self, predicate_name: str) -> list[PddlAction]:
        return [
            action
            for action in self._actions.values()
            if any(
                literal.predicate == predicate_name
                for literal in chain(action.conditions, action.effects)
            )
        ]

    # Checking.

    def _check(self, batch: _Batch) -> None:
        if batch.check_everything:
            proposition_keys: Iterable[PropositionKey] = self._propositions
            action_names: Iterable[str] = self._actions
        else:
            proposition_keys = batch.propositions_to_check
            action_names = batch.actions_to_check
        for key in proposition_keys:
            proposition = self._propositions.get(key)
            if proposition is not None:
                self._check_proposition(proposition)
        for name in action_names:
            action = self._actions.get(name)
            if action is not None:
                self._check_action(action)

    def _signature(self, predicate_name: str, user: str, arity: int) -> tuple[str, ...]:
        predicate = self._predicates.get(predicate_name)
        if predicate is None:
            raise KnowledgeError(
                f"{user} uses unknown predicate {predicate_name!r}; "
                f"save Predicate({predicate_name!r}, [...]) first"
            )
        parameter_types = predicate.parameter_types
        if len(parameter_types) != arity:
            raise KnowledgeError(
                f"{user} gives {arity} argument(s) to {predicate_name!r}, which takes "
                f"{len(parameter_types)}: ({', '.join(parameter_types)})"
            )
        return parameter_types

    def _check_proposition(self, proposition: Proposition) -> None:
        user = f"proposition {proposition}"
        expected_types = self._signature(proposition.predicate, user, len(proposition.objects))
        for position, (name, expected) in enumerate(
            zip(proposition.objects, expected_types, strict=True), 1
        ):
            pddl_object = self._objects.get(name)
            if pddl_object is None:
                raise KnowledgeError(
                    f"{user} uses unknown object {name!r}; save PddlObject({name!r}, type) first"
                )
            actual = pddl_object.type
            if not self.is_subtype(actual, expected):
                raise KnowledgeError(
                    f"{user}: object {name!r} has type {actual!r}, but argument {position} of "
                    f"{proposition.predicate!r} must be a {expected!r}"
                )

    def _check_action(self, action: PddlAction) -> None:
        literal: TimedLiteral
        for literal in chain(action.conditions, action.effects):
            user = f"action {action.name!r}"
            expected_types = self._signature(literal.predicate, user, len(literal.arguments))
            for position, (argument, expected) in enumerate(
                zip(literal.arguments, expected_types, strict=True), 1
            ):
                actual = action.parameter_type(argument)
                if not self.is_subtype(actual, expected):
                    raise KnowledgeError(
                        f"{user}: parameter {argument!r} has type {actual!r}, but argument "
                        f"{position} of {literal.predicate!r} must be a {expected!r}"
                    )

    # Bookkeeping.

    def _put(self, kind: ItemKind, key: Hashable, item: KnowledgeItem, batch: _Batch) -> None:
        batch.originals.setdefault((kind, key), self._items[kind].get(key))
        self._raw_put(kind, key, item)

    def _remove(self, kind: ItemKind, key: Hashable, batch: _Batch) -> None:
        if key in self._items[kind]:
            batch.originals.setdefault((kind, key), self._items[kind][key])
            self._raw_remove(kind, key)

    def _raw_put(self, kind: ItemKind, key: Hashable, item: KnowledgeItem) -> None:
        self._raw_remove(kind, key)
        self._items[kind][key] = item
        if isinstance(item, Proposition):
            for name in item.objects:
                self._propositions_by_object.setdefault(name, {})[item.key] = None

    def _raw_remove(self, kind: ItemKind, key: Hashable) -> None:
        item = self._items[kind].pop(key, None)
        if isinstance(item, Proposition):
            for name in item.objects:
                users = self._propositions_by_object.get(name)
                if users is not None:
                    users.pop(item.key, None)
                    if not users:
                        del self._propositions_by_object[name]

    def _restore(self, originals: Originals) -> None:
        for (kind, key), original in originals.items():
            if original is None:
                self._raw_remove(kind, key)
            else:
                self._raw_put(kind, key, original)

    def _net_events(self, originals: Originals) -> tuple[ChangeEvent, ...]:
        deleted: dict[ItemKind, list[ChangeEvent]] = {kind: [] for kind in ItemKind}
        saved: dict[ItemKind, list[ChangeEvent]] = {kind: [] for kind in ItemKind}
        for (kind, key), original in originals.items():
            current = self._items[kind].get(key)
            if current is not None and current != original:
                saved[kind].append(ChangeEvent(Operation.SAVE, kind, current))
            elif current is None and original is not None:
                deleted[kind].append(ChangeEvent(Operation.DELETE, kind, original))
        return tuple(
            chain(
                chain.from_iterable(deleted[kind] for kind in DELETE_ORDER),
                chain.from_iterable(saved[kind] for kind in SAVE_ORDER),
            )
        )
