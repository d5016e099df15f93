"""The default store: everything in memory, gone when the process ends.

Right for tests, simulations and short missions; the rules are the same as for the persistent
stores because they all share :class:`~merlin2_sailor.knowledge.mirrored_store.MirroredStore`.
"""

from collections.abc import Iterable, Sequence

from merlin2_sailor.knowledge.changes import ChangeEvent
from merlin2_sailor.knowledge.mirrored_store import MirroredStore
from merlin2_sailor.knowledge.model import KnowledgeItem
from merlin2_sailor.knowledge.store import DEFAULT_TIMEOUT_SECONDS


class MemoryStore(MirroredStore):
    """A knowledge base with no database behind its in-memory state."""

    @classmethod
    def from_location(cls, location: str, timeout: float = DEFAULT_TIMEOUT_SECONDS) -> "MemoryStore":
        """``memory``: nothing to find, nothing to wait for."""
        return cls()

    def _load(self) -> Iterable[KnowledgeItem]:
        return ()

    def _persist(self, events: Sequence[ChangeEvent]) -> None:
        """Nothing to write: memory already holds the batch."""

    def _close_database(self) -> None:
        """Nothing to release."""
