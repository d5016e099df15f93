"""The vocabulary of writing to a knowledge base: what to change, and what did change.

A :class:`Change` is a request, which may turn out to change nothing (saving what is already
there); a :class:`ChangeEvent` reports a change that really happened, after cascades. Keeping the
two apart is what lets stores promise that subscribers only hear about real changes.
"""

from collections.abc import Hashable, Mapping
from dataclasses import dataclass
from enum import Enum
from types import MappingProxyType

from merlin2_sailor.errors import KnowledgeError
from merlin2_sailor.knowledge.model import (
    KnowledgeItem,
    PddlAction,
    PddlObject,
    PddlType,
    Predicate,
    Proposition,
)


class Operation(Enum):
    """Save (create or update) or delete; the values are those of KANT's update services."""

    SAVE = 0
    DELETE = 1


class ItemKind(Enum):
    """The five kinds of item a knowledge base keeps, each with its own data access object."""

    TYPE = "type"
    OBJECT = "object"
    PREDICATE = "predicate"
    PROPOSITION = "proposition"
    ACTION = "action"


_KIND_OF_CLASS: Mapping[type, ItemKind] = MappingProxyType(
    {
        PddlType: ItemKind.TYPE,
        PddlObject: ItemKind.OBJECT,
        Predicate: ItemKind.PREDICATE,
        Proposition: ItemKind.PROPOSITION,
        PddlAction: ItemKind.ACTION,
    }
)


def kind_of(item: KnowledgeItem) -> ItemKind:
    """The kind of a model item, or a clear error for anything else."""
    try:
        return _KIND_OF_CLASS[type(item)]
    except KeyError:
        raise KnowledgeError(
            f"{item!r} is not a knowledge item; store a PddlType, PddlObject, Predicate, "
            "Proposition or PddlAction"
        ) from None


def key_of(item: KnowledgeItem) -> Hashable:
    """The identity a store keeps an item under: its name, or a proposition's key."""
    if isinstance(item, Proposition):
        return item.key
    return item.name


@dataclass(frozen=True)
class Change:
    """One requested save or delete, built with :meth:`save`, :meth:`delete` or :meth:`delete_key`.

    A delete needs only the kind and key, so callers may delete by name without knowing, say,
    the type of the object they delete.
    """

    operation: Operation
    kind: ItemKind
    key: Hashable
    item: KnowledgeItem | None = None

    def __post_init__(self) -> None:
        if self.item is None:
            if self.operation is Operation.SAVE:
                raise KnowledgeError("a save needs the item to save; use Change.save(item)")
        elif kind_of(self.item) is not self.kind or key_of(self.item) != self.key:
            raise KnowledgeError(
                f"change names {self.kind.value} {self.key!r} but carries {self.item!r}; "
                "build it with Change.save(item) or Change.delete(item)"
            )

    @classmethod
    def save(cls, item: KnowledgeItem) -> "Change":
        """Create the item, or update the stored item with the same key."""
        return cls(Operation.SAVE, kind_of(item), key_of(item), item)

    @classmethod
    def delete(cls, item: KnowledgeItem) -> "Change":
        """Delete the stored item with this item's key, and everything that refers to it."""
        return cls(Operation.DELETE, kind_of(item), key_of(item), item)

    @classmethod
    def delete_key(cls, kind: ItemKind, key: Hashable) -> "Change":
        """Delete by key alone, e.g. an object by its name."""
        return cls(Operation.DELETE, kind, key)


@dataclass(frozen=True)
class ChangeEvent:
    """A change that happened: the item as saved, or as it was just before it was deleted."""

    operation: Operation
    kind: ItemKind
    item: KnowledgeItem
