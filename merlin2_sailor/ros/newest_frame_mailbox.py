"""A small mailbox between a subscription and a worker thread: the newest frames win.

A node whose work per frame can take longer than the frame period must not let its DDS queue
pile up stale frames (latency grows to queue depth x period) nor lose them silently when the
queue overflows: it hands each frame to this mailbox, which keeps only the newest ``capacity``
of them and counts the ones it let go, and a worker takes them one at a time, oldest first.

One slot suits a node whose frames are images (the detector, the percept generator): an image
superseded by a newer one is worth nothing. A node whose frames are evidence that adds up (the
anchoring node: every sighting counts towards confirming a new object) keeps a few, so that a
burst of work (the camera sweeping past a shelf of new books, each crop to embed) is caught up
on instead of losing the very sightings that would confirm them; a sustained overload still
drops frames, at most ``capacity`` frame periods behind the camera.
"""

from __future__ import annotations

import threading
from collections import deque
from typing import Any


class NewestFrameMailbox:
    """A mailbox of at most ``capacity`` frames: a frame arriving when it is full pushes out the
    oldest waiting one. ``dropped`` counts the frames pushed out before the worker took them."""

    def __init__(self, capacity: int = 1) -> None:
        if capacity < 1:
            raise ValueError(f"a frame mailbox holds at least one frame, got capacity {capacity}")
        self._condition = threading.Condition()
        self._waiting: deque[Any] = deque()
        self._capacity = capacity
        self._closed = False
        self.dropped = 0

    @property
    def capacity(self) -> int:
        return self._capacity

    def put(self, frame: Any) -> None:
        with self._condition:
            if len(self._waiting) == self._capacity:
                self._waiting.popleft()
                self.dropped += 1
            self._waiting.append(frame)
            self._condition.notify()

    def take(self) -> Any:
        """Block until a frame is waiting and return the oldest; None once the mailbox is closed."""
        with self._condition:
            self._condition.wait_for(lambda: bool(self._waiting) or self._closed)
            if self._closed:
                return None
            return self._waiting.popleft()

    def close(self) -> None:
        with self._condition:
            self._closed = True
            self._condition.notify_all()
