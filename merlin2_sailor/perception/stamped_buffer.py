"""StampedBuffer: the latest few stamped values, looked up by the stamp nearest to a query.

Percepts reach the anchoring layer some milliseconds after the camera pose and depth image of
the same instant. To judge what the camera saw (which anchors were in view, which were hidden),
the anchoring node looks those up by the percepts' stamp. A bounded buffer keeps this O(size)
and never grows. Subscriptions add while a worker thread looks up, so both hold a lock.
"""

from __future__ import annotations

import threading
from collections import deque
from typing import Generic, TypeVar

ValueT = TypeVar("ValueT")


class StampedBuffer(Generic[ValueT]):
    def __init__(self, capacity: int = 60, tolerance: float = 0.05) -> None:
        if capacity < 1 or tolerance < 0.0:
            raise ValueError("capacity must be at least 1 and tolerance not negative")
        self._entries: deque[tuple[float, ValueT]] = deque(maxlen=capacity)
        self._tolerance = tolerance
        self._lock = threading.Lock()

    def add(self, stamp: float, value: ValueT) -> None:
        with self._lock:
            self._entries.append((stamp, value))

    def nearest(self, stamp: float) -> ValueT | None:
        """The value stamped nearest to ``stamp``, if within the tolerance; else None."""
        with self._lock:
            entries = tuple(self._entries)
        best: tuple[float, ValueT] | None = None
        for entry_stamp, value in entries:
            gap = abs(entry_stamp - stamp)
            if gap <= self._tolerance and (best is None or gap < best[0]):
                best = (gap, value)
        return best[1] if best is not None else None

    def latest(self) -> ValueT | None:
        with self._lock:
            return self._entries[-1][1] if self._entries else None
