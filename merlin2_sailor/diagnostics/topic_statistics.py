"""Rate and age of the messages on one topic over a sliding time window.

``ros2 topic hz`` is not installable from PyPI; this is the arithmetic behind the topic monitor
node, kept free of ROS so it can be tested with synthetic arrival times.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass


@dataclass(frozen=True)
class TopicReport:
    """What happened on a topic during the window that ends now."""

    messages: int  # received in the window
    rate_hz: float  # messages per second over the window (0 with fewer than two messages)
    mean_age_seconds: float | None  # arrival time minus header stamp; None without stamps
    total_messages: int  # received since the start


class TopicStatistics:
    """Keep arrival times (and optional header stamps) of the last ``window_seconds``."""

    def __init__(self, window_seconds: float = 5.0) -> None:
        if window_seconds <= 0.0:
            raise ValueError("window_seconds must be positive")
        self._window = window_seconds
        self._arrivals: deque[float] = deque()
        self._ages: deque[tuple[float, float]] = deque()
        self._total = 0

    def record(self, arrival_seconds: float, stamp_seconds: float | None = None) -> None:
        """Record one message arriving at ``arrival_seconds`` (a monotonic or ROS clock)."""
        self._arrivals.append(arrival_seconds)
        if stamp_seconds is not None and stamp_seconds > 0.0:
            self._ages.append((arrival_seconds, arrival_seconds - stamp_seconds))
        self._total += 1
        self._forget_before(arrival_seconds - self._window)

    def report(self, now_seconds: float) -> TopicReport:
        self._forget_before(now_seconds - self._window)
        count = len(self._arrivals)
        rate = (count - 1) / (self._arrivals[-1] - self._arrivals[0]) if count >= 2 else 0.0
        if count >= 2 and self._arrivals[-1] == self._arrivals[0]:
            rate = 0.0
        ages = [age for _, age in self._ages]
        mean_age = sum(ages) / len(ages) if ages else None
        return TopicReport(count, rate, mean_age, self._total)

    def _forget_before(self, oldest_kept: float) -> None:
        while self._arrivals and self._arrivals[0] < oldest_kept:
            self._arrivals.popleft()
        while self._ages and self._ages[0][0] < oldest_kept:
            self._ages.popleft()
