"""Open a knowledge base by its location, so the choice of store is one line of configuration.

A location is ``scheme://rest`` or a bare name (``memory``); its scheme picks a store class from
:data:`STORES`, a table of ``"module:Class"`` strings, so only the chosen store is imported (a
robot on SQLite never needs pymongo or KANT), and the class opens the location with its
``from_location``. The table holds the ROS-free stores only: the ROS layer extends it with
``ros://`` (the knowledge_base node) in :mod:`merlin2_sailor.ros.stores`, so this layer never
names a module above it. Adding a store is one module with a ``KnowledgeBase`` subclass that has a
``from_location``, plus one line here (or in the table of the layer it belongs to).
"""

from __future__ import annotations

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.knowledge.store import DEFAULT_TIMEOUT_SECONDS, KnowledgeBase
from merlin2_sailor.plugins import PluginTable

MEMORY = "memory"
SCHEME_SEPARATOR = "://"

#: Scheme -> "module:Class" of every ROS-free store.
STORES = PluginTable(
    "knowledge store",
    {
        MEMORY: "merlin2_sailor.knowledge.memory_store:MemoryStore",
        "sqlite": "merlin2_sailor.knowledge.sqlite_store:SqliteStore",
        "mongodb": "merlin2_sailor.knowledge.mongo_store:MongoStore",
        "mongodb+srv": "merlin2_sailor.knowledge.mongo_store:MongoStore",
        "kant+mongodb": "merlin2_sailor.knowledge.kant_store:KantStore",
    },
)

#: What the error for an unknown location shows, so a user sees the forms, not only the names.
LOCATION_FORMS = (
    "memory, sqlite:///absolute/path.db, sqlite://relative/path.db, mongodb://host:port/database, "
    "kant+mongodb://host:port/database; from ROS nodes and `sailor` commands also ros:///namespace "
    "(the knowledge_base node) and kant+ros:///namespace (KANT's node, MERLIN2's knowledge base), "
    "see merlin2_sailor.ros.stores"
)


def scheme_of(location: str) -> str:
    """``"sqlite:///kb.db"`` -> ``"sqlite"``; a location without ``://`` is its own scheme."""
    scheme, separator, _rest = location.partition(SCHEME_SEPARATOR)
    return scheme if separator else location


def open_store(
    location: str = MEMORY, timeout: float = DEFAULT_TIMEOUT_SECONDS, stores: PluginTable = STORES
) -> KnowledgeBase:
    """Open the store a location names, from ``stores`` (the ROS-free ones by default).

    ``timeout`` bounds the wait for a server, for the stores that have one (MongoDB, ROS).

    Raises:
        ConfigurationError: the location names no known store, or is malformed.
        DependencyError: the store's library is not installed.
        KnowledgeError: the database cannot be opened.
    """
    scheme = scheme_of(location)
    if scheme not in stores:
        raise ConfigurationError(
            f"unknown knowledge store {location!r} (scheme {scheme!r}; known: {', '.join(stores.names)}); "
            f"write one of {LOCATION_FORMS}"
        )
    store_class: type[KnowledgeBase] = stores.load(scheme)
    return store_class.from_location(location, timeout=timeout)
