"""A one-slot mailbox between a subscription and a worker thread: the newest frame wins.

A node whose work per frame can take longer than the frame period must not let its DDS queue
pile up stale frames (latency grows to queue depth x period) nor lose them silently when the
queue overflows: it hands each frame to this mailbox, which keeps only the newest and counts the
ones it replaced, and a worker takes them one at a time.
"""

from __future__ import annotations

import threading
from typing import Any


class NewestFrameMailbox:
    """A one-slot mailbox between a subscription and a worker: a newer frame replaces a waiting one.

    ``dropped`` counts the frames replaced before the worker took them, i.e. the frames that
    arrived while the worker was busy with an older one.
    """

    def __init__(self) -> None:
        self._condition = threading.Condition()
        self._waiting: Any = None
        self._closed = False
        self.dropped = 0

    def put(self, frame: Any) -> None:
        with self._condition:
            if self._waiting is not None:
                self.dropped += 1
            self._waiting = frame
            self._condition.notify()

    def take(self) -> Any:
        """Block until a frame is waiting and return it; None once the mailbox is closed."""
        with self._condition:
            self._condition.wait_for(lambda: self._waiting is not None or self._closed)
            if self._closed:
                return None
            frame, self._waiting = self._waiting, None
            return frame

    def close(self) -> None:
        with self._condition:
            self._closed = True
            self._condition.notify_all()
