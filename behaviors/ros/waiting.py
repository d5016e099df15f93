"""Waiting for an rclpy future from a thread that is not the executor's, without ever hanging.

The behaviours' clients make blocking calls from the state machine's worker thread while the
node's executor serves the responses on its own threads. Every wait is bounded, polls a
cancellation check, and gives up at once when the node is stopping (after its executor has shut
down, no response would ever arrive). A goal's result is waited for by
:func:`wait_for_goal_result`, which also recovers a result response lost on the way.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from enum import Enum
from typing import Any

from action_msgs.msg import GoalStatus

POLL_SECONDS = 0.02

#: The goal statuses after which a goal runs no more.
GOAL_ENDED = frozenset({GoalStatus.STATUS_SUCCEEDED, GoalStatus.STATUS_CANCELED, GoalStatus.STATUS_ABORTED})


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


#: How long (s) a goal may stand finished, by its status, with its result not in, before the
#: result is asked for again (a result response lost on the way is never sent twice by itself).
RESULT_REQUERY_SECONDS = 1.0


@dataclass(frozen=True)
class GoalWait:
    """How waiting for a goal's result ended: ``response`` is the GetResult response when ``end``
    is DONE; ``requeries`` counts the result requests sent again after a lost response."""

    end: WaitEnd
    response: Any = None
    requeries: int = 0


def wait_for_goal_result(
    handle: Any,
    timeout: float | None,
    stopping: threading.Event,
    should_cancel: Callable[[], bool] | None = None,
    requery_after: float = RESULT_REQUERY_SECONDS,
) -> GoalWait:
    """Wait for the result of the accepted goal ``handle`` (an rclpy ClientGoalHandle).

    The goal's status (which the action client hears on the status topic) says when the goal has
    ended; a result that has not arrived ``requery_after`` seconds later was lost, and is asked for
    again (the server keeps it). Ends as :func:`wait_for` does otherwise.
    """
    future = handle.get_result_async()
    deadline = None if timeout is None else time.monotonic() + timeout
    ended_since: float | None = None
    requeries = 0
    while True:
        if future.done() and future.result() is not None:
            return GoalWait(WaitEnd.DONE, future.result(), requeries)
        if stopping.is_set():
            return GoalWait(WaitEnd.STOPPING, None, requeries)
        if should_cancel is not None and should_cancel():
            return GoalWait(WaitEnd.CANCELED, None, requeries)
        now = time.monotonic()
        if deadline is not None and now >= deadline:
            return GoalWait(WaitEnd.TIMEOUT, None, requeries)
        if handle.status in GOAL_ENDED:
            ended_since = now if ended_since is None else ended_since
            if now - ended_since >= requery_after:
                future = handle.get_result_async()
                requeries += 1
                ended_since = now
        stopping.wait(POLL_SECONDS)
