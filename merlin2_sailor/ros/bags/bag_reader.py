"""BagReader: the topics and messages of a rosbag2 bag, as the message classes the nodes use.

A bag is a rosbag2 folder (``metadata.yaml`` beside its ``.mcap`` or ``.db3`` files) or a bare
``.mcap`` / ``.db3`` file. What can go wrong with one (no such path, not a bag, a file cut short
by a recorder that was killed, a topic that is not there, a type that is not installed) is one
ConfigurationError or InvalidInputError whose message says which and what to do, never a
traceback of the library below.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rclpy.serialization import deserialize_message
from rosbags.rosbag2 import Reader
from rosbags.rosbag2.errors import ReaderError

from merlin2_sailor.errors import ConfigurationError, InvalidInputError
from merlin2_sailor.ros.conversions.message_types import message_class


@dataclass(frozen=True, slots=True)
class BagMessage:
    """One message of a bag: its topic, the time it was recorded (ns) and the message itself."""

    topic: str
    recorded_ns: int
    message: Any


class BagReader:
    """Open with ``with BagReader(path) as bag:``; then :attr:`topics` and :meth:`messages`."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path).expanduser()
        if not self.path.exists():
            raise ConfigurationError(f"no bag at {self.path}")
        self._reader: Reader | None = None
        self.topics: dict[str, str] = {}

    def __enter__(self) -> BagReader:
        try:
            reader = Reader(self.path)
            reader.open()
        except FileNotFoundError as error:
            raise ConfigurationError(
                f"{self.path} is not a rosbag2 bag: a bag is a folder with metadata.yaml, or an .mcap or .db3 "
                f"file ({error})") from None
        except (ReaderError, OSError, ValueError, KeyError, IndexError) as error:
            raise ConfigurationError(
                f"cannot read the bag {self.path}: it is damaged or cut short (a recorder that was killed leaves "
                f"it so; `ros2 bag reindex` or `mcap recover` may mend it): {_describe(error)}") from None
        self._reader = reader
        for connection in reader.connections:
            self.topics[connection.topic] = connection.msgtype
        return self

    def __exit__(self, *_exception: object) -> None:
        if self._reader is not None:
            try:
                self._reader.close()
            except (ReaderError, OSError):
                pass
            self._reader = None

    def require(self, topic: str, what: str, option: str) -> str:
        """The type of ``topic``; a clear error naming the bag's topics when it is not there."""
        if topic not in self.topics:
            listed = ", ".join(f"{name} ({kind})" for name, kind in sorted(self.topics.items())) or "none"
            raise ConfigurationError(
                f"the bag {self.path} has no topic {topic} ({what}); name the right one with {option}. "
                f"Its topics: {listed}")
        return self.topics[topic]

    def messages(self, topics: Iterable[str]) -> Iterator[BagMessage]:
        """The messages of ``topics`` in recorded order, deserialised into rclpy's message classes.

        A message that does not decode is an InvalidInputError naming its topic and time; a bag
        cut short ends with a ConfigurationError after the messages before the cut.
        """
        reader = self._open()
        wanted = set(topics)
        connections = [connection for connection in reader.connections if connection.topic in wanted]
        classes = {connection.id: self._class_of(connection.topic, connection.msgtype) for connection in connections}
        iterator = reader.messages(connections=connections)
        while True:
            try:
                connection, recorded_ns, data = next(iterator)
            except StopIteration:
                return
            except (ReaderError, OSError, ValueError, KeyError, IndexError, EOFError) as error:
                raise ConfigurationError(
                    f"the bag {self.path} is damaged or cut short (a recorder that was killed leaves it so): "
                    f"{_describe(error)}") from None
            try:
                message = deserialize_message(bytes(data), classes[connection.id])
            except Exception as error:  # noqa: BLE001 - rclpy raises bare exceptions for bad CDR
                raise InvalidInputError(
                    f"the message of {connection.topic} recorded at {recorded_ns / 1e9:.3f} s does not decode as "
                    f"{connection.msgtype}: {_describe(error)}") from None
            yield BagMessage(connection.topic, recorded_ns, message)

    def _class_of(self, topic: str, type_name: str) -> Any:
        try:
            return message_class(type_name)
        except InvalidInputError:
            raise InvalidInputError(
                f"the bag's topic {topic} holds {type_name}, which is not installed here; install its "
                "interface package (a ROS workspace, or SAILOR_UPSTREAM for vision_msgs and yolo_msgs)") from None

    def _open(self) -> Reader:
        if self._reader is None:
            raise ConfigurationError("the bag is not open: use `with BagReader(path) as bag:`")
        return self._reader


def _describe(error: BaseException) -> str:
    return str(error).strip() or type(error).__name__
