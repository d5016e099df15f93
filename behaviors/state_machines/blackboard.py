"""The data a state machine's states share during one run, as YASMIN 3.2's Blackboard holds it.

Unlike py_trees' class-level storage, a :class:`Blackboard` is an ordinary object: a machine run
gets one (a new one when the caller passes none), so two runs, two machines or two tests never
see each other's keys. It is lock-protected because a state may hand work to a thread, and a
canceller may read progress while the state runs.

It offers what YASMIN's offers and no more (``[key]``, ``in``, ``del``, ``len``), so a behaviour
that runs here runs on YASMIN: no iteration, no ``get``. Remappings are YASMIN's too: while a
state runs, its machine sets ``remappings`` (the state's key -> the blackboard's key), which
reads, ``in`` and ``del`` follow; writes, as in YASMIN 3.2, go to the key as written.
"""

import threading
from collections.abc import Mapping
from typing import Any


class Blackboard:
    """A lock-protected store of named values for one run of a state machine."""

    def __init__(self, init: Mapping[str, Any] | None = None) -> None:
        self._lock = threading.RLock()
        self._values: dict[str, Any] = dict(init or {})
        self._remappings: dict[str, str] = {}

    @property
    def remappings(self) -> dict[str, str]:
        """The running state's view: its key -> the key it reads on this blackboard."""
        return self._remappings

    @remappings.setter
    def remappings(self, remappings: Mapping[str, str]) -> None:
        self._remappings = dict(remappings)

    def _remap(self, key: str) -> str:
        return self._remappings.get(key, key)

    def __getitem__(self, key: str) -> Any:
        with self._lock:
            try:
                return self._values[self._remap(key)]
            except KeyError:
                raise KeyError(f"blackboard has no key {key!r}; it holds {sorted(self._values)}") from None

    def __setitem__(self, key: str, value: Any) -> None:
        with self._lock:
            self._values[key] = value

    def __delitem__(self, key: str) -> None:
        with self._lock:
            del self._values[self._remap(key)]

    def __contains__(self, key: object) -> bool:
        with self._lock:
            return isinstance(key, str) and self._remap(key) in self._values

    def __len__(self) -> int:
        with self._lock:
            return len(self._values)

    def __repr__(self) -> str:
        with self._lock:
            return f"Blackboard({self._values!r})"
