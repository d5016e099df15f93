"""A knowledge base in MongoDB, the database KANT and MERLIN2 use, for sharing with their tools.

pymongo is imported only when a MongoStore is created, so the rest of the package works without
it. Each kind of item is a collection of documents whose ``_id`` is the item's key.

MongoDB has no multi-document transaction outside replica sets, so a batch is written as one
ordered bulk write per run of same-kind changes; since events come dependents-first for deletes
and dependencies-first for saves, a crash part-way leaves a consistent, if older, state.
"""

from collections.abc import Iterable, Sequence
from itertools import groupby
from typing import Any

from merlin2_sailor.errors import DependencyError, KnowledgeError
from merlin2_sailor.knowledge.changes import ChangeEvent, Operation
from merlin2_sailor.knowledge.codec import COLLECTION_NAMES, from_document, key_text, to_document
from merlin2_sailor.knowledge.mirrored_store import MirroredStore
from merlin2_sailor.knowledge.model import KnowledgeItem
from merlin2_sailor.knowledge.rules import SAVE_ORDER
from merlin2_sailor.knowledge.store import DEFAULT_TIMEOUT_SECONDS

DEFAULT_DATABASE = "merlin2_sailor"
"""Used when the URI names no database."""


def _import_pymongo() -> Any:
    try:
        import pymongo
    except ImportError as error:
        raise DependencyError(
            "the MongoDB knowledge base needs pymongo; install it with "
            "'pip install pymongo', or choose the 'memory' or 'sqlite://' store"
        ) from error
    return pymongo


class MongoStore(MirroredStore):
    """A knowledge base persisted in a MongoDB database, e.g. ``mongodb://localhost:27017/kb``."""

    def __init__(self, uri: str, timeout_seconds: float = DEFAULT_TIMEOUT_SECONDS) -> None:
        super().__init__()
        pymongo = _import_pymongo()
        self._errors = pymongo.errors.PyMongoError
        self._bulk_requests = (pymongo.ReplaceOne, pymongo.DeleteOne)
        self.uri = uri
        try:
            self._client = pymongo.MongoClient(
                uri, serverSelectionTimeoutMS=int(timeout_seconds * 1000)
            )
            self._client.admin.command("ping")
            self._database = self._client.get_default_database(default=DEFAULT_DATABASE)
            self._open_mirror()
        except (self._errors, pymongo.errors.ConfigurationError) as error:
            raise KnowledgeError(
                f"cannot use MongoDB knowledge base {uri!r} ({error}); start the server or "
                "check the URI (mongodb://host:port/database)"
            ) from error

    @classmethod
    def from_location(cls, location: str, timeout: float = DEFAULT_TIMEOUT_SECONDS) -> "MongoStore":
        """A MongoDB URI, ``mongodb://host:port/database`` or ``mongodb+srv://...``, as it is."""
        return cls(location, timeout_seconds=timeout)

    def _load(self) -> Iterable[KnowledgeItem]:
        items = []
        for kind in SAVE_ORDER:
            for document in self._database[COLLECTION_NAMES[kind]].find({}, {"_id": False}):
                items.append(from_document(kind, document))
        return items

    def _persist(self, events: Sequence[ChangeEvent]) -> None:
        replace, delete = self._bulk_requests
        try:
            for (operation, kind), group in groupby(
                events, key=lambda event: (event.operation, event.kind)
            ):
                if operation is Operation.SAVE:
                    requests = [
                        replace(
                            {"_id": key_text(event.item)},
                            {"_id": key_text(event.item), **to_document(event.item)},
                            upsert=True,
                        )
                        for event in group
                    ]
                else:
                    requests = [delete({"_id": key_text(event.item)}) for event in group]
                self._database[COLLECTION_NAMES[kind]].bulk_write(requests, ordered=True)
        except self._errors as error:
            raise KnowledgeError(
                f"could not write to MongoDB knowledge base {self.uri!r} ({error}); the batch "
                "was not applied in memory and may be partly written: reopen the store to reload"
            ) from error

    def _close_database(self) -> None:
        self._client.close()
