"""Where and when the robot last looked all around, so that a look is not repeated at once.

Navigation looks around on arrival when it expects anchored objects at the destination; a plan
that then explores the same waypoint would turn through another 360 degrees to see the same
things. A look counts for a place only while the robot has not left it and for ``fresh_for``
seconds; after that the world may have changed and a look is a look again.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class Look:
    """One complete look-around: at which place, where exactly (x, y, metres) and when (clock seconds)."""

    place: str
    x: float
    y: float
    time: float


class LookHistory:
    """The latest complete look-around; shared by every behaviour of one process (thread-safe)."""

    def __init__(self, clock: Callable[[], float] = time.monotonic) -> None:
        self._clock = clock
        self._lock = threading.Lock()
        self._latest: Look | None = None

    def record(self, place: str, x: float, y: float) -> None:
        with self._lock:
            self._latest = Look(place, x, y, self._clock())

    def forget(self) -> None:
        with self._lock:
            self._latest = None

    def recent(self, place: str, x: float, y: float, fresh_for: float, still_within: float = 0.3) -> Look | None:
        """The latest look if it was at ``place``, from within ``still_within`` m of (x, y), at most
        ``fresh_for`` seconds ago; else None."""
        with self._lock:
            look = self._latest
        if look is None or look.place != place or self._clock() - look.time > fresh_for:
            return None
        return look if math.hypot(look.x - x, look.y - y) <= still_within else None
