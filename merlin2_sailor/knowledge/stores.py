"""Open a knowledge base by name, so the choice of store is one line of configuration.

Store modules are imported only when chosen: a robot using SQLite never needs pymongo. The
``ros://`` store is the knowledge_base node reached over ROS services; its client lives with the
other ROS code and is imported by name only when chosen, so this layer stays ROS-free.
"""

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.knowledge.store import KnowledgeBase

MEMORY = "memory"
SQLITE_PREFIX = "sqlite://"
MONGODB_PREFIXES = ("mongodb://", "mongodb+srv://")
ROS_PREFIX = "ros://"


def open_store(location: str = MEMORY) -> KnowledgeBase:
    """Open the store a location names.

    * ``"memory"``: in memory, the default;
    * ``"sqlite://"`` followed by a path: ``sqlite:///var/lib/kb.db`` (absolute),
      ``sqlite://kb.db`` (relative to the working directory) or ``sqlite://:memory:``;
    * a MongoDB URI: ``mongodb://host:port/database``;
    * ``"ros://"`` followed by the knowledge_base node's namespace: ``ros:///merlin2``.

    Raises:
        ConfigurationError: the location names no known store.
        DependencyError: the store's library is not installed.
        KnowledgeError: the database cannot be opened.
    """
    if location == MEMORY:
        from merlin2_sailor.knowledge.memory_store import MemoryStore

        return MemoryStore()
    if location.startswith(SQLITE_PREFIX):
        path = location.removeprefix(SQLITE_PREFIX)
        if not path:
            raise ConfigurationError(
                f"{location!r} names no file; write sqlite:///absolute/path.db or sqlite://:memory:"
            )
        from merlin2_sailor.knowledge.sqlite_store import SqliteStore

        return SqliteStore(path)
    if location.startswith(MONGODB_PREFIXES):
        from merlin2_sailor.knowledge.mongo_store import MongoStore

        return MongoStore(location)
    if location.startswith(ROS_PREFIX):
        from merlin2_sailor.ros.knowledge_base_client import RemoteKnowledgeBase

        return RemoteKnowledgeBase(namespace=location.removeprefix(ROS_PREFIX) or "/")
    raise ConfigurationError(
        f"unknown knowledge store {location!r}; use 'memory', 'sqlite:///path/to/file.db', "
        "'mongodb://host:port/database' or 'ros:///namespace'"
    )
