"""Which state a running machine is in, down through nested machines, for progress feedback.

Works on the local state machines and on real YASMIN alike: both offer ``get_current_state()``
and ``get_states()`` (entries with a ``state``, as an attribute or a key).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

MAX_DEPTH = 16


def active_state_path(machine: Any) -> str:
    """``"SEARCHING/LOOKING_AROUND"``: the running state at each level, "" between runs."""
    names: list[str] = []
    current = machine
    for _level in range(MAX_DEPTH):
        get_current = getattr(current, "get_current_state", None)
        get_states = getattr(current, "get_states", None)
        if get_current is None or get_states is None:
            break
        name = get_current()
        if not name:
            break
        names.append(str(name))
        entry = get_states().get(name)
        if isinstance(entry, Mapping):
            current = entry.get("state")
        else:
            current = getattr(entry, "state", None)
        if current is None:
            break
    return "/".join(names)
