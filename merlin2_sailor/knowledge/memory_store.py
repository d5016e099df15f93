"""The default store: everything in memory, gone when the process ends.

Right for tests, simulations and short missions; the rules are the same as for the persistent
stores because they all share :class:`~merlin2_sailor.knowledge.mirrored_store.MirroredStore`.
"""

from collections.abc import Iterable, Sequence

from merlin2_sailor.knowledge.changes import ChangeEvent
from merlin2_sailor.knowledge.mirrored_store import MirroredStore
from merlin2_sailor.knowledge.model import KnowledgeItem


class MemoryStore(MirroredStore):
    """A knowledge base with no database behind its in-memory state."""

    def __init__(self) -> None:
        super().__init__()
        self._last_symbol_index: dict[str, int] = {}

    def _load(self) -> Iterable[KnowledgeItem]:
        return ()

    def _persist(self, events: Sequence[ChangeEvent]) -> None:
        """Nothing to write: memory already holds the batch."""

    def _reserve_symbol_index(self, class_identifier: str) -> int:
        index = self._last_symbol_index.get(class_identifier, 0) + 1
        self._last_symbol_index[class_identifier] = index
        return index

    def _close_database(self) -> None:
        """Nothing to release."""
