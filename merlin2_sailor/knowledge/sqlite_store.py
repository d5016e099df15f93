"""A knowledge base in one SQLite file: persistent, dependency-free, fast enough for a robot.

Each kind of item is a table of ``(key, document)`` rows holding the codec's JSON, because the
store answers reads from memory (see :mod:`~merlin2_sailor.knowledge.mirrored_store`) and only
needs the database to survive restarts. WAL journaling with ``synchronous=NORMAL`` keeps a commit
cheap and never corrupts the file; a power cut may lose the last batches, which perception
rebuilds within a frame.
"""

import json
import sqlite3
from collections.abc import Iterable, Sequence
from itertools import groupby
from pathlib import Path

from merlin2_sailor.errors import ConfigurationError, KnowledgeError
from merlin2_sailor.knowledge.changes import ChangeEvent, Operation
from merlin2_sailor.knowledge.codec import COLLECTION_NAMES, from_document, key_text, to_document
from merlin2_sailor.knowledge.mirrored_store import MirroredStore
from merlin2_sailor.knowledge.model import KnowledgeItem
from merlin2_sailor.knowledge.rules import SAVE_ORDER
from merlin2_sailor.knowledge.store import DEFAULT_TIMEOUT_SECONDS

SCHEMA_VERSION = 1
"""Stored in ``PRAGMA user_version``, so a future layout can recognise and migrate this one.

Files written before the anchoring node owned the symbol counters hold an unused
``symbol_counters`` table; it is left alone."""

SCHEME = "sqlite://"


class SqliteStore(MirroredStore):
    """A knowledge base persisted in a SQLite file, or in ``":memory:"`` for throwaway use."""

    def __init__(self, path: str | Path = ":memory:") -> None:
        super().__init__()
        self.path = str(path)
        try:
            if self.path != ":memory:":
                # A fresh robot has no data folder yet; a path like ~/.sailor/kb.db should just work.
                Path(self.path).expanduser().parent.mkdir(parents=True, exist_ok=True)
            # The store's lock serialises every use, so the connection may cross threads.
            self._connection = sqlite3.connect(self.path, check_same_thread=False)
            self._create_schema()
            self._open_mirror()
        except (sqlite3.Error, OSError) as error:
            raise KnowledgeError(
                f"cannot open SQLite knowledge base {self.path!r} ({error}); check that the "
                "directory exists and is writable"
            ) from error

    @classmethod
    def from_location(cls, location: str, timeout: float = DEFAULT_TIMEOUT_SECONDS) -> "SqliteStore":
        """``sqlite:///absolute/kb.db``, ``sqlite://relative/kb.db`` or ``sqlite://:memory:``."""
        path = location.removeprefix(SCHEME)
        if not path:
            raise ConfigurationError(f"{location!r} names no file; write sqlite:///absolute/path.db or sqlite://:memory:")
        return cls(path)

    def _create_schema(self) -> None:
        connection = self._connection
        version = connection.execute("PRAGMA user_version").fetchone()[0]
        if version not in (0, SCHEMA_VERSION):
            raise KnowledgeError(
                f"{self.path!r} has knowledge-base schema {version}, this version reads "
                f"{SCHEMA_VERSION}; upgrade merlin2_sailor or use another file"
            )
        connection.execute("PRAGMA journal_mode=WAL")
        connection.execute("PRAGMA synchronous=NORMAL")
        with connection:
            for table in COLLECTION_NAMES.values():
                connection.execute(
                    f"CREATE TABLE IF NOT EXISTS {table} "
                    "(key TEXT PRIMARY KEY, document TEXT NOT NULL)"
                )
            connection.execute(f"PRAGMA user_version={SCHEMA_VERSION}")

    def _load(self) -> Iterable[KnowledgeItem]:
        for kind in SAVE_ORDER:
            rows = self._connection.execute(
                f"SELECT document FROM {COLLECTION_NAMES[kind]} ORDER BY rowid"
            ).fetchall()
            for (document,) in rows:
                yield from_document(kind, json.loads(document))

    def _persist(self, events: Sequence[ChangeEvent]) -> None:
        try:
            with self._connection:  # One transaction: commits on success, rolls back on error.
                for (operation, kind), group in groupby(
                    events, key=lambda event: (event.operation, event.kind)
                ):
                    table = COLLECTION_NAMES[kind]
                    if operation is Operation.SAVE:
                        self._connection.executemany(
                            f"INSERT INTO {table} (key, document) VALUES (?, ?) "
                            "ON CONFLICT(key) DO UPDATE SET document = excluded.document",
                            [
                                (key_text(event.item), json.dumps(to_document(event.item)))
                                for event in group
                            ],
                        )
                    else:
                        self._connection.executemany(
                            f"DELETE FROM {table} WHERE key = ?",
                            [(key_text(event.item),) for event in group],
                        )
        except sqlite3.Error as error:
            raise KnowledgeError(
                f"could not write to SQLite knowledge base {self.path!r} ({error}); "
                "nothing of the batch was applied"
            ) from error

    def _close_database(self) -> None:
        self._connection.close()
