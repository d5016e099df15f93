"""The text definitions of message types, which a rosbag2 bag stores beside each topic.

A bag records each topic's type with its full definition (so that a reader without the type
installed can still decode it). ``rosbags`` ships the definitions of ROS 2 Jazzy's standard
types; the others (this project's interfaces, vision_msgs, yolo_msgs) are read from the
``share/<package>/msg/<Type>.msg`` files their builds install, found through AMENT_PREFIX_PATH
and this Python environment's prefix, then registered with their nested types.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

from merlin2_sailor.errors import ConfigurationError

TYPE_STORE = Stores.ROS2_JAZZY


def jazzy_typestore() -> Typestore:
    """A fresh typestore with ROS 2 Jazzy's standard types (each writer extends its own)."""
    return get_typestore(TYPE_STORE)


def share_prefixes() -> list[Path]:
    """Where interface packages are installed: AMENT_PREFIX_PATH's entries, then this environment."""
    prefixes = [Path(entry) for entry in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if entry]
    return [*prefixes, Path(sys.prefix)]


def definition_file(type_name: str) -> Path | None:
    """The installed ``.msg`` file of ``package/msg/Type``, or None."""
    package, _, name = type_name.split("/")
    for prefix in share_prefixes():
        candidate = prefix / "share" / package / "msg" / f"{name}.msg"
        if candidate.is_file():
            return candidate
    return None


def register_type(store: Typestore, type_name: str) -> None:
    """Make ``type_name`` (``package/msg/Type``) and every type it nests known to ``store``.

    Raises ConfigurationError naming the type when no definition of it is installed.
    """
    pending = [type_name]
    while pending:
        name = pending.pop()
        if name in store.fielddefs:
            continue
        parts = name.split("/")
        if len(parts) != 3:
            raise ConfigurationError(f"'{name}' is not a message type name like 'package/msg/Type'")
        path = definition_file(name)
        if path is None:
            raise ConfigurationError(
                f"no definition of {name} is installed (looked for share/{parts[0]}/msg/{parts[2]}.msg under "
                f"AMENT_PREFIX_PATH and {sys.prefix}); cannot record its topic")
        types = get_types_from_msg(path.read_text(), name)
        store.register(types)
        for _, (_, fields) in types.items():
            for _field_name, (kind, description) in fields:
                pending.extend(_nested_names(kind, description))


def _nested_names(kind: object, description: object) -> list[str]:
    """The message type names a field of a parsed definition refers to (itself, or its elements)."""
    kind_name = getattr(kind, "name", "")
    if kind_name == "NAME":
        return [str(description)]
    if kind_name in ("ARRAY", "SEQUENCE"):
        (element_kind, element), _size = description  # type: ignore[misc]
        if getattr(element_kind, "name", "") == "NAME":
            return [str(element)]
    return []
