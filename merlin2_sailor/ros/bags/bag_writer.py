"""BagWriter: a rosbag2 bag written from serialised messages, MCAP (compressed) or SQLite3.

The recorder hands it the CDR bytes DDS delivered (a raw subscription), so nothing is decoded
and encoded again on the way; the bag stores each topic's type with its definition
(:mod:`.message_definitions`), so Foxglove, RViz's bag tools and ``ros2 bag`` read it.
"""

from __future__ import annotations

from pathlib import Path
from types import MappingProxyType

from rosbags.interfaces import Connection
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.rosbag2.enums import CompressionFormat, CompressionMode
from rosbags.rosbag2.errors import WriterError

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.ros.bags.message_definitions import jazzy_typestore, register_type

#: Storage name -> rosbags plugin. MCAP is rosbag2's default since Iron and what Foxglove opens.
BAG_STORAGES = MappingProxyType({"mcap": StoragePlugin.MCAP, "sqlite3": StoragePlugin.SQLITE3})
BAG_VERSION = 9  # rosbag2's format since Jazzy


class BagWriter:
    """Create with the bag folder's path (it must not exist), ``add_topic``, ``write``, ``close``."""

    def __init__(self, path: str | Path, storage: str = "mcap") -> None:
        if storage not in BAG_STORAGES:
            raise ConfigurationError(f"unknown bag storage '{storage}'; choose one of {', '.join(BAG_STORAGES)}")
        self.path = Path(path).expanduser()
        if self.path.exists():
            raise ConfigurationError(f"{self.path} exists already; a bag is never written over")
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._typestore = jazzy_typestore()
        self._writer = Writer(self.path, version=BAG_VERSION, storage_plugin=BAG_STORAGES[storage])
        if storage == "mcap":
            # Chunk compression: camera frames of the simulated house shrink several times over.
            self._writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
        try:
            self._writer.open()
        except (WriterError, OSError) as error:
            raise ConfigurationError(f"cannot create the bag {self.path}: {error}") from None
        self._connections: dict[str, Connection] = {}
        self.counts: dict[str, int] = {}

    def add_topic(self, topic: str, type_name: str) -> None:
        """Record ``topic`` of ``type_name`` (``package/msg/Type``); its definition must be installed."""
        if topic in self._connections:
            return
        register_type(self._typestore, type_name)
        self._connections[topic] = self._writer.add_connection(topic, type_name, typestore=self._typestore)
        self.counts[topic] = 0

    def write(self, topic: str, recorded_ns: int, data: bytes) -> None:
        self._writer.write(self._connections[topic], recorded_ns, data)
        self.counts[topic] += 1

    def close(self) -> None:
        self._writer.close()
