"""The data a state machine's states share during one run.

Unlike py_trees' class-level storage, a :class:`Blackboard` is an ordinary object: a machine run
gets one (a new one when the caller passes none), so two runs, two machines or two tests never
see each other's keys. It is a thread-safe mutable mapping because a state may hand work to a
thread, and a canceller may read progress while the state runs.
"""

import threading
from collections.abc import Iterator, Mapping, MutableMapping
from typing import Any


class Blackboard(MutableMapping[str, Any]):
    """A dict-like, lock-protected store of named values for one run of a state machine."""

    def __init__(self, initial: Mapping[str, Any] | None = None) -> None:
        self._lock = threading.RLock()
        self._values: dict[str, Any] = dict(initial or {})

    def __getitem__(self, key: str) -> Any:
        with self._lock:
            try:
                return self._values[key]
            except KeyError:
                raise KeyError(
                    f"blackboard has no key {key!r}; it holds {sorted(self._values)}"
                ) from None

    def __setitem__(self, key: str, value: Any) -> None:
        with self._lock:
            self._values[key] = value

    def __delitem__(self, key: str) -> None:
        with self._lock:
            del self._values[key]

    def __iter__(self) -> Iterator[str]:
        with self._lock:
            return iter(list(self._values))

    def __len__(self) -> int:
        with self._lock:
            return len(self._values)

    def __repr__(self) -> str:
        with self._lock:
            return f"Blackboard({self._values!r})"
