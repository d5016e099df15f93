"""MERLIN2's knowledge base (KANT's node in /merlin2), waited for with a deadline.

KANT's DAOs, which every MERLIN2 node uses (an action registering itself, a mission saving its
goals), wait for KANT's services without a deadline: started before KANT's node, or without it,
they hang. SAILOR's MERLIN2 tools first wait, up to a deadline, until KANT answers a real request
(through the ``kant+ros`` store, whose every exchange has one), and otherwise stop with one line.
"""

from __future__ import annotations

import time

from merlin2_sailor.errors import KnowledgeError

KANT_LOCATION = "kant+ros:///merlin2"
"""MERLIN2's knowledge base: KANT's node in MERLIN2's fixed namespace."""
PROBE_SECONDS = 2.0


def wait_for_kant(timeout: float, location: str = KANT_LOCATION) -> None:
    """Return once KANT's node answers, asking again until ``timeout`` seconds have passed.

    Raises:
        KnowledgeError: KANT did not answer in time; the message says what was asked of whom.
    """
    from merlin2_sailor.ros.stores import open_store

    deadline = time.monotonic() + timeout
    while True:
        try:
            open_store(location, timeout=PROBE_SECONDS).close()
            return
        except KnowledgeError as error:
            if time.monotonic() >= deadline:
                raise KnowledgeError(f"{error} (waited {timeout:g} s)") from error
        time.sleep(min(PROBE_SECONDS / 4, max(0.0, deadline - time.monotonic())))
