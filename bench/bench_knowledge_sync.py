"""How long it takes to write a frame in which 1,000 anchors all moved into the SQLite store.

Run ``python bench/bench_knowledge_sync.py``. It prints figures and asserts nothing. The batched
path is KnowledgeSync (grounding + diff + one ``apply``); the baseline sends exactly the same
changes one store call each, the way a node without batching would, so the ratio isolates the
cost of one transaction per fact. Target for the batched path: 100 ms or less.
"""

import argparse
import os
import platform
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from merlin2_sailor.knowledge import (
    Change,
    Grounding,
    GroundingConfig,
    KnowledgeBase,
    KnowledgeSync,
)
from merlin2_sailor.knowledge.sqlite_store import SqliteStore

WAYPOINT_COUNT = 50
WAYPOINT_SPACING_METRES = 2.0
TARGET_MILLISECONDS = 100.0


@dataclass(frozen=True)
class BenchAnchor:
    symbol: str
    class_name: str
    position: np.ndarray
    state: str = "confirmed"
    visible: bool = True


def grounding() -> Grounding:
    waypoints = {f"wp{i}": [i * WAYPOINT_SPACING_METRES, 0.0] for i in range(WAYPOINT_COUNT)}
    return Grounding(
        GroundingConfig.from_mapping(
            {"map": {"waypoints": waypoints}, "class_types": {"cup": "cup", "book": "book"}}
        )
    )


def frame(anchor_count: int, number: int) -> list[BenchAnchor]:
    """Every anchor one waypoint further than in the previous frame: every location changes."""
    return [
        BenchAnchor(
            f"{'cup' if i % 2 else 'book'}_{i}",
            "cup" if i % 2 else "book",
            np.array([((i + number) % WAYPOINT_COUNT) * WAYPOINT_SPACING_METRES, 0.1, 0.8]),
        )
        for i in range(anchor_count)
    ]


def one_call_per_change(store: KnowledgeBase, changes: tuple[Change, ...]) -> None:
    for change in changes:
        store.apply([change])


def measure(
    directory: Path,
    name: str,
    anchor_count: int,
    frames: int,
    write: Callable[[KnowledgeBase, tuple[Change, ...]], None] | None,
) -> tuple[list[float], int]:
    """Milliseconds per changed frame (plan + write), and changes per frame.

    ``write`` None means the sync's own single batch; otherwise it sends the planned changes.
    """
    with SqliteStore(directory / f"{name}.db") as store:
        sync = KnowledgeSync(store, grounding())
        sync.sync(frame(anchor_count, 0))  # Fills the store; not timed.
        timings = []
        change_count = 0
        for number in range(1, frames + 1):
            anchors = frame(anchor_count, number)
            start = time.perf_counter()
            plan = sync.plan(anchors)
            if write is None:
                sync.sync(anchors)
            else:
                write(store, plan.changes)
                sync.sync(anchors)  # Nothing left to write; keeps the sync's view current.
            timings.append((time.perf_counter() - start) * 1000.0)
            change_count = len(plan.changes)
        sync.close()
    return timings, change_count


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--anchors", type=int, default=1000)
    parser.add_argument("--frames", type=int, default=5)
    arguments = parser.parse_args()

    print(
        f"machine: {platform.platform()}, {platform.processor() or platform.machine()}, "
        f"{os.cpu_count()} CPUs, Python {platform.python_version()}"
    )
    print(f"{arguments.anchors} anchors, every one moved in each of {arguments.frames} frames")
    with tempfile.TemporaryDirectory() as directory:
        batched, changes = measure(
            Path(directory), "batched", arguments.anchors, arguments.frames, None
        )
        naive, _ = measure(
            Path(directory), "naive", arguments.anchors, arguments.frames, one_call_per_change
        )
    batched_ms, naive_ms = statistics.median(batched), statistics.median(naive)
    print(f"changes per frame: {changes}")
    print(
        f"batched (KnowledgeSync, one transaction): median {batched_ms:8.1f} ms, "
        f"min {min(batched):.1f}, max {max(batched):.1f}  (target <= {TARGET_MILLISECONDS:.0f} ms)"
    )
    print(
        f"naive (one store call per change):        median {naive_ms:8.1f} ms, "
        f"min {min(naive):.1f}, max {max(naive):.1f}"
    )
    print(f"ratio naive / batched: {naive_ms / batched_ms:.1f}x")


if __name__ == "__main__":
    main()
