"""The machinery every local store shares: rules in memory, then one write to a database.

A local store is the single writer of its database (MERLIN2 runs one knowledge-base node, and
other processes reach it through that node), so it reads the database once when it opens and
then answers every read from memory. That makes checking a batch against the rules and finding
what a batch really changed pure in-memory work; the database only receives the net changes, in
one write per batch. Subclasses say how to load and how to write, nothing else, so the rules in
:mod:`~merlin2_sailor.knowledge.rules` are the same for every store.
"""

import logging
import threading
from abc import abstractmethod
from collections.abc import Hashable, Iterable, Sequence

from merlin2_sailor.errors import KnowledgeError
from merlin2_sailor.knowledge.changes import Change, ChangeEvent, ItemKind
from merlin2_sailor.knowledge.model import KnowledgeItem, Proposition
from merlin2_sailor.knowledge.rules import KnowledgeState
from merlin2_sailor.knowledge.store import KnowledgeBase, Subscriber, Unsubscribe

_logger = logging.getLogger(__name__)


class MirroredStore(KnowledgeBase):
    """A knowledge base that keeps all items in memory and writes each batch to a database.

    Thread-safe: ROS executors may call it from several threads, so a re-entrant lock makes each
    batch, and the events it causes, one indivisible step. Subscribers run inside that step, so
    they see batches in order and must be quick.
    """

    def __init__(self) -> None:
        super().__init__()
        self._state = KnowledgeState()
        self._lock = threading.RLock()
        self._subscribers: list[Subscriber] = []
        self._closed = False

    # What a subclass provides.

    @abstractmethod
    def _load(self) -> Iterable[KnowledgeItem]:
        """Every item already in the database."""

    @abstractmethod
    def _persist(self, events: Sequence[ChangeEvent]) -> None:
        """Write a batch's net changes in one transaction, or raise and write nothing.

        Events come deletions first, dependents first, then saves, dependencies first, so even a
        database without multi-document transactions holds a consistent state after any prefix.
        """

    @abstractmethod
    def _close_database(self) -> None:
        """Release the connection."""

    def _open_mirror(self) -> None:
        """Fill memory from the database; subclasses call this once they are connected."""
        self._state.load(self._load())

    # The port.

    def get(self, kind: ItemKind, key: Hashable) -> KnowledgeItem | None:
        with self._lock:
            return self._state.get(kind, key)

    def get_all(self, kind: ItemKind) -> tuple[KnowledgeItem, ...]:
        with self._lock:
            return self._state.get_all(kind)

    def propositions_about(self, object_name: str) -> tuple[Proposition, ...]:
        with self._lock:
            return self._state.propositions_about(object_name)

    def apply(self, changes: Iterable[Change]) -> tuple[ChangeEvent, ...]:
        with self._lock:
            self._require_open()
            transaction = self._state.apply(changes)
            if not transaction.events:
                return ()
            try:
                self._persist(transaction.events)
            except BaseException:
                transaction.rollback()
                raise
            self._notify(transaction.events)
            return transaction.events

    def subscribe(self, subscriber: Subscriber) -> Unsubscribe:
        with self._lock:
            self._subscribers.append(subscriber)

        def unsubscribe() -> None:
            with self._lock:
                if subscriber in self._subscribers:
                    self._subscribers.remove(subscriber)

        return unsubscribe

    def close(self) -> None:
        with self._lock:
            if not self._closed:
                self._closed = True
                self._close_database()

    # Helpers.

    def _require_open(self) -> None:
        if self._closed:
            raise KnowledgeError(f"{type(self).__name__} is closed; open a new store to write")

    def _notify(self, events: tuple[ChangeEvent, ...]) -> None:
        # The batch is already committed: a failing subscriber must not make the caller believe
        # it was not, nor keep the other subscribers from hearing about it.
        for subscriber in tuple(self._subscribers):
            try:
                subscriber(events)
            except Exception:
                _logger.exception("knowledge-base subscriber %r failed; continuing", subscriber)
