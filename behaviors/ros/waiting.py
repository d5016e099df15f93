"""Waiting for an rclpy future from a thread that is not the executor's, without ever hanging.

The behaviours' clients make blocking calls from the state machine's worker thread while the
node's executor serves the responses on its own threads. Every wait is bounded, polls a
cancellation check, and gives up at once when the node is stopping (after its executor has shut
down, no response would ever arrive).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from enum import Enum
from typing import Any

POLL_SECONDS = 0.02


class WaitEnd(Enum):
    DONE = "done"
    TIMEOUT = "timeout"
    CANCELED = "canceled"
    STOPPING = "stopping"


def wait_for(
    ready: Callable[[], bool],
    timeout: float | None,
    stopping: threading.Event,
    should_cancel: Callable[[], bool] | None = None,
) -> WaitEnd:
    """Poll ``ready`` until it is true, the timeout passes (None: never), ``should_cancel()``
    becomes true or ``stopping`` is set, whichever comes first."""
    deadline = None if timeout is None else time.monotonic() + timeout
    while True:
        if ready():
            return WaitEnd.DONE
        if stopping.is_set():
            return WaitEnd.STOPPING
        if should_cancel is not None and should_cancel():
            return WaitEnd.CANCELED
        if deadline is not None and time.monotonic() >= deadline:
            return WaitEnd.TIMEOUT
        stopping.wait(POLL_SECONDS)


def wait_for_future(
    future: Any,
    timeout: float | None,
    stopping: threading.Event,
    should_cancel: Callable[[], bool] | None = None,
) -> WaitEnd:
    """:func:`wait_for` an rclpy future to be done."""
    return wait_for(future.done, timeout, stopping, should_cancel)
