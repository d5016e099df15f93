"""How long it takes to write a frame in which 1,000 anchors all moved into the SQLite store.

Run ``python bench/bench_knowledge_sync.py [--anchors N] [--frames N] [--quick] [--json PATH]``.
It prints figures and asserts nothing. The batched path is KnowledgeSync (grounding + diff + one
``apply``); the baseline sends exactly the same changes one store call each, the way a node
without batching would, so the ratio isolates the cost of one transaction per fact. Target for
the batched path: 100 ms or less.
"""

import argparse
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from harness import script
from harness.results import BenchmarkResult, Table

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


def run(quick: bool = False, anchors: int = 0, frames: int = 0) -> BenchmarkResult:
    anchor_count = anchors or (300 if quick else 1000)
    frame_count = frames or (3 if quick else 5)
    print(f"  {anchor_count} anchors, every one moved in each of {frame_count} frames", flush=True)
    with tempfile.TemporaryDirectory() as directory:
        batched, changes = measure(Path(directory), "batched", anchor_count, frame_count, None)
        naive, _ = measure(Path(directory), "naive", anchor_count, frame_count, one_call_per_change)
    batched_ms, naive_ms = statistics.median(batched), statistics.median(naive)
    result = BenchmarkResult(
        "knowledge_sync", "Knowledge-base sync of a frame: one batch vs one store call per change",
        f"{anchor_count} anchors in the SQLite store, every one moved to another waypoint in each of {frame_count} "
        f"frames ({changes} changes per frame); median per frame of planning plus writing. Ours: KnowledgeSync "
        "(grounding, diff, one transaction). Baseline: exactly the same changes, one store call each.",
        parameters={"anchors": anchor_count, "frames": frame_count, "changes_per_frame": changes},
    )
    result.figure(f"{anchor_count} anchors moved, batched", batched_ms, "ms/frame", baseline=naive_ms,
                  baseline_name="one call per change", target=f"<= {TARGET_MILLISECONDS:.0f} ms",
                  met=batched_ms <= TARGET_MILLISECONDS)
    result.tables.append(Table("per frame", ["path", "median ms", "min ms", "max ms"], [
        ["batched (one transaction)", round(batched_ms, 1), round(min(batched), 1), round(max(batched), 1)],
        ["one store call per change", round(naive_ms, 1), round(min(naive), 1), round(max(naive), 1)],
    ]))
    return result


def main() -> int:
    def extend(parser: argparse.ArgumentParser) -> None:
        parser.add_argument("--anchors", type=int, default=0, help="anchors (default 1000, quick 300)")
        parser.add_argument("--frames", type=int, default=0, help="frames (default 5, quick 3)")

    return script.main(run, __doc__, extend=extend)


if __name__ == "__main__":
    raise SystemExit(main())
