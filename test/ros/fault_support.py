"""What the fault and bad-input tests share: service calls, log counting, the stand-in scripts.

test/ros is not a package: the tests put this folder on sys.path to import it, with
:mod:`network_split` and :mod:`split_roles`.
"""

from __future__ import annotations

import math
import re
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
SPLIT_ROLES = HERE / "split_roles.py"


def call_service(probe: Any, service_type: Any, name: str, request: Any, timeout: float = 20.0) -> Any:
    """Call a service from the probe node; None when it does not appear or answer in time."""
    client = probe.node.create_client(service_type, name)
    try:
        if not client.wait_for_service(timeout_sec=timeout):
            return None
        future = client.call_async(request)
        if not probe.wait_for(future.done, timeout):
            client.remove_pending_request(future)
            return None
        return future.result()
    finally:
        probe.node.destroy_client(client)


BURST = 200  # identical bad messages, to check that their rejection is rate limited
BURST_PAUSE = 0.01  # seconds between two messages of a burst: fast, but not faster than a node reads
BATCH_PAUSE = 0.004  # between two messages of a random batch
WARNING_PERIOD = 5.0  # the nodes log one kind of rejection at most once per this many seconds
_LOG_LINE = re.compile(r"^\[(?P<level>[A-Z]+)\] \[(?P<stamp>\d+\.\d+)\] \[[^\]]+\]: (?P<text>.*)$")


def log_records(text: str) -> list[tuple[str, float, str]]:
    """(level, wall-clock stamp, text) of each log line of a node's output."""
    records = []
    for line in text.splitlines():
        match = _LOG_LINE.match(line)
        if match:
            records.append((match["level"], float(match["stamp"]), match["text"]))
    return records


def assert_rate_limited(text: str, fragment: str, started: float, ended: float) -> None:
    """A burst of bad messages is logged, with a reason, at most once per warning period.

    The line may come from just before the burst (the same rejection, less than a period earlier,
    holds the rate limiter); the burst itself may add one line per period it lasted.
    """
    lines = [(stamp, line) for _, stamp, line in log_records(text) if fragment in line]
    recent = [line for stamp, line in lines if started - WARNING_PERIOD <= stamp <= ended + 1.0]
    during = [line for stamp, line in lines if started <= stamp <= ended + 1.0]
    allowed = 1 + math.ceil((ended - started) / WARNING_PERIOD)
    assert recent, f"no {fragment!r} line for a burst of {BURST} bad messages:\n{text}"
    assert len(during) <= allowed, f"{len(during)} {fragment!r} lines for one burst (at most {allowed}):\n{text}"
    assert all(line.split(fragment, 1)[1].strip(" :") for line in recent), f"a rejection without a reason: {recent}"


def publish_burst(publisher: Any, make_message: Callable[[], Any]) -> tuple[float, float]:
    started = time.time()
    for _ in range(BURST):
        publisher.publish(make_message())
        time.sleep(BURST_PAUSE)
    return started, time.time()


def publish_batch(publishers: dict[str, Any], batch: list[tuple[str, Any]]) -> None:
    for topic, message in batch:
        publishers[topic].publish(message)
        time.sleep(BATCH_PAUSE)


def output_of(handle: Any) -> str:
    """A node's whole output, for a failure message: stops the node if it is still running."""
    handle.stop()
    return handle.text
