"""Message classes found by their ROS type names, for nodes that handle topics of any type."""

from __future__ import annotations

import importlib
from typing import Any

from merlin2_sailor.errors import InvalidInputError


def message_class(type_name: str) -> Any:
    """Import a message class from its ROS type name, e.g. 'sensor_msgs/msg/Image'."""
    parts = type_name.split("/")
    if len(parts) != 3 or parts[1] not in ("msg", "srv", "action"):
        raise InvalidInputError(f"'{type_name}' is not a ROS type name like 'package/msg/Type'")
    package, kind, name = parts
    try:
        return getattr(importlib.import_module(f"{package}.{kind}"), name)
    except (ImportError, AttributeError) as error:
        raise InvalidInputError(f"message type '{type_name}' is not installed") from error
