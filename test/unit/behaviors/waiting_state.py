"""A state that runs until it is cancelled, for the mission tests."""

from __future__ import annotations

import threading
import time

from merlin2_sailor_behaviors.state_machines import CANCEL, SUCCEED, Blackboard, State

#: How long the state waits for its cancellation before giving up (the test then fails).
WAIT_SECONDS = 5.0


class WaitForCancel(State):
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

