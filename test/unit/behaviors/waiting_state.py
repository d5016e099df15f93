"""A state that runs until it is cancelled, shared by the state-machine and mission tests."""

from __future__ import annotations

import threading
import time

from merlin2_sailor_behaviors.state_machines import CANCEL, SUCCEED, Blackboard, State
from merlin2_sailor_behaviors.state_machines import state as local_state

#: How long the state waits for its cancellation before giving up (the test then fails).
WAIT_SECONDS = 5.0


class _WaitForCancel:
    """Runs until cancelled, telling the test when it has started."""

    def __init__(self) -> None:
        super().__init__([SUCCEED, CANCEL])
        self.started = threading.Event()

    def execute(self, blackboard: Blackboard) -> str:
        self.started.set()
        deadline = time.monotonic() + WAIT_SECONDS
        while not self.is_canceled() and time.monotonic() < deadline:
            time.sleep(0.002)
        return CANCEL if self.is_canceled() else SUCCEED


class WaitForCancel(_WaitForCancel, State):
    """On the state-machine implementation the behaviours run on (real YASMIN or the local one)."""


class LocalWaitForCancel(_WaitForCancel, local_state.State):
    """On the project's own implementation, for the tests of that implementation."""
