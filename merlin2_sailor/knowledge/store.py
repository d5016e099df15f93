"""The knowledge-base port: what the rest of SAILOR may ask of any knowledge base.

Everything above the knowledge layer (the sync, the ROS nodes, behaviours) depends on
:class:`KnowledgeBase` only, so a store can be memory, SQLite, MongoDB or MERLIN2's own KB node
behind ROS services without any caller changing. The per-kind verbs are KANT's data access
objects, so code written against KANT reads the same here.
"""

from abc import ABC, abstractmethod
from collections.abc import Callable, Hashable, Iterable, Sequence
from types import TracebackType
from typing import Generic, TypeVar

from merlin2_sailor.knowledge.changes import Change, ChangeEvent, ItemKind
from merlin2_sailor.knowledge.model import (
    KnowledgeItem,
    PddlAction,
    PddlObject,
    PddlType,
    Predicate,
    Proposition,
)

DEFAULT_TIMEOUT_SECONDS = 5.0
"""How long a store that talks to a server (MongoDB, the knowledge_base node) waits for it."""

Subscriber = Callable[[Sequence[ChangeEvent]], None]
"""Called once per applied batch with the events it caused; never with an empty sequence."""

Unsubscribe = Callable[[], None]
"""Returned by :meth:`KnowledgeBase.subscribe`; calling it again is harmless."""

ItemT = TypeVar("ItemT", PddlType, PddlObject, Predicate, Proposition, PddlAction)


class DataAccessObject(Generic[ItemT]):
    """KANT's five verbs for one kind of item, each a one-change batch on the store."""

    def __init__(self, store: "KnowledgeBase", kind: ItemKind, item_class: type[ItemT]) -> None:
        self._store = store
        self._kind = kind
        self._item_class: type[ItemT] = item_class

    def get(self, key: Hashable) -> ItemT | None:
        """The item with this name (a proposition: this :attr:`Proposition.key`), or None."""
        return self._store.get(self._kind, key)  # type: ignore[return-value]

    def get_all(self) -> tuple[ItemT, ...]:
        """Every stored item of this kind."""
        return self._store.get_all(self._kind)  # type: ignore[return-value]

    def save(self, item: ItemT) -> tuple[ChangeEvent, ...]:
        """Create or update the item; saving an equal item again changes nothing."""
        return self._store.apply([Change.save(item)])

    def delete(self, item_or_key: ItemT | Hashable) -> tuple[ChangeEvent, ...]:
        """Delete an item, given itself or its key, with everything that refers to it."""
        if isinstance(item_or_key, self._item_class):
            return self._store.apply([Change.delete(item_or_key)])
        return self._store.apply([Change.delete_key(self._kind, item_or_key)])

    def delete_all(self) -> tuple[ChangeEvent, ...]:
        """Delete every item of this kind, in one batch, with everything that refers to them."""
        return self._store.apply([Change.delete(item) for item in self._store.get_all(self._kind)])


class KnowledgeBase(ABC):
    """A knowledge base of PDDL types, objects, predicates, propositions and actions.

    Writes go through :meth:`apply`, one batch at a time, whole or not at all; the rules they
    obey are those of :mod:`~merlin2_sailor.knowledge.rules`. Use a store as a context manager,
    or call :meth:`close`, to release its database.
    """

    def __init__(self) -> None:
        self.types = DataAccessObject(self, ItemKind.TYPE, PddlType)
        self.objects = DataAccessObject(self, ItemKind.OBJECT, PddlObject)
        self.predicates = DataAccessObject(self, ItemKind.PREDICATE, Predicate)
        self.propositions = DataAccessObject(self, ItemKind.PROPOSITION, Proposition)
        self.actions = DataAccessObject(self, ItemKind.ACTION, PddlAction)

    @abstractmethod
    def get(self, kind: ItemKind, key: Hashable) -> KnowledgeItem | None:
        """The item of a kind stored under ``key``, or None."""

    @abstractmethod
    def get_all(self, kind: ItemKind) -> tuple[KnowledgeItem, ...]:
        """Every stored item of a kind."""

    @abstractmethod
    def propositions_about(self, object_name: str) -> tuple[Proposition, ...]:
        """The facts and goals that use an object, without reading every proposition."""

    @abstractmethod
    def apply(self, changes: Iterable[Change]) -> tuple[ChangeEvent, ...]:
        """Apply a batch of changes in one transaction and return the changes that happened.

        Raises:
            KnowledgeError: a change breaks a rule, or the database refused the write; nothing
                of the batch was applied.
        """

    @abstractmethod
    def subscribe(self, subscriber: Subscriber) -> Unsubscribe:
        """Call ``subscriber`` after every batch that changed something."""

    @abstractmethod
    def close(self) -> None:
        """Release the database; closing twice is harmless."""

    @classmethod
    def from_location(cls, location: str, timeout: float = DEFAULT_TIMEOUT_SECONDS) -> "KnowledgeBase":
        """Open the store that ``location`` names; its scheme chose this class (see ``stores``).

        ``timeout`` bounds the wait for a server, for the stores that have one.
        """
        raise NotImplementedError(f"{cls.__name__} is not opened by location; construct it directly")

    def __enter__(self) -> "KnowledgeBase":
        return self

    def __exit__(
        self,
        exception_type: type[BaseException] | None,
        exception: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()
