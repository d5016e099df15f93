"""Per-frame anchoring cost as anchors pile up far from the camera, and the memory they take.

A robot that has mapped a large building keeps thousands of anchors, almost all of them far from
where it looks now. The frame loop must not pay for them: gating and the visibility check ask a
k-d tree for nearby anchors only. Scene: 20 objects 2-4 m in front of the camera, seen every
frame (percepts with 1,280-d embeddings, a depth image for the occlusion test), plus N anchors
acquired earlier 30-230 m away, each seen four times (full appearance galleries). The matcher is
the rule matcher (the network's cost depends on the pairs that pass the gate, not on N; see
bench_matching.py). Targets: per-frame cost flat within 2x from 100 to 10,000 far anchors;
<= 300 MB for 10,000 anchors. One thread. Nothing is asserted.

Run: python bench/bench_anchoring_scale.py [--quick] [--json PATH]
"""

# ruff: noqa: E402 - the thread limits must be set before NumPy and torch are imported
from __future__ import annotations

import os

for variable in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[variable] = "1"

import gc
import statistics
import time
import tracemalloc

import numpy as np
import torch
from bench_matching import FEATURE_DIMENSION, GALLERY_VIEWS
from harness import script
from harness.results import BenchmarkResult, LinePlot, Table

from merlin2_sailor.anchoring import Anchoring, CameraView
from merlin2_sailor.anchoring.service import AnchoringService
from merlin2_sailor.anchoring.settings import OFFLINE_OVERRIDES, load_anchoring_settings
from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.percept import BoundingBox2D, Percept
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.resources import config_file

LOCAL_OBJECTS = 20
FRAMES = 100
INTRINSICS = CameraIntrinsics(fx=525.0, fy=525.0, cx=319.5, cy=239.5, width=640, height=480)
#: Camera at (0, 0, 1) looking along world +x (optical z forward, x right, y down).
CAMERA = Pose(np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]]), np.array([0.0, 0.0, 1.0]))


def percept(
    class_name: str, position: np.ndarray, embedding: np.ndarray, stamp: float, rng: np.random.Generator
) -> Percept:
    return Percept(
        class_name=class_name,
        score=0.8,
        box=BoundingBox2D(320.0, 240.0, 60.0, 60.0),
        position=position + rng.normal(scale=0.01, size=3),
        size=np.array([0.2, 0.2, 0.3]),
        stamp=stamp,
        embedding=embedding + rng.normal(scale=0.01, size=embedding.shape).astype(np.float32),
    )


def acquire_far_anchors(anchoring: Anchoring, count: int, rng: np.random.Generator) -> float:
    """Acquire ``count`` anchors 30-230 m away, each seen GALLERY_VIEWS times; returns the last stamp."""
    positions = np.column_stack(
        (rng.uniform(30.0, 230.0, count), rng.uniform(-100.0, 100.0, count), rng.uniform(0.0, 2.0, count))
    )
    embeddings = rng.random((count, FEATURE_DIMENSION), dtype=np.float32)
    stamp = 0.0
    for start in range(0, count, 200):
        batch = range(start, min(start + 200, count))
        for _ in range(GALLERY_VIEWS):
            stamp += 0.1
            percepts = [percept(f"class_{i % 50}", positions[i], embeddings[i], stamp, rng) for i in batch]
            anchoring.process(percepts, None, stamp)
    return stamp


def new_anchoring() -> Anchoring:
    """The deployed anchoring layer (config/anchoring.yaml, offline, the rule matcher), confirming
    after GALLERY_VIEWS sightings; the far anchors are acquired without a camera view, so they are
    never "missing" and stay."""
    settings = load_anchoring_settings(
        config_file("anchoring.yaml"),
        overrides={**OFFLINE_OVERRIDES, "matcher": "rules", "confirm_after": GALLERY_VIEWS})
    return AnchoringService(settings).anchoring


def frame_cost_ms(far_anchors: int, rng: np.random.Generator, frames: int = FRAMES) -> tuple[float, int]:
    anchoring = new_anchoring()
    stamp = acquire_far_anchors(anchoring, far_anchors, rng)
    local_positions = np.column_stack(
        [rng.uniform(low, high, LOCAL_OBJECTS) for low, high in ((2.0, 4.0), (-1.0, 1.0), (0.5, 1.5))]
    )
    local_embeddings = rng.random((LOCAL_OBJECTS, FEATURE_DIMENSION), dtype=np.float32)
    view = CameraView(INTRINSICS, CAMERA, np.full((INTRINSICS.height, INTRINSICS.width), 5.0, dtype=np.float32))
    times = []
    for frame in range(frames + 5):
        stamp += 1.0 / 15.0
        percepts = [
            percept(f"class_{i}", local_positions[i], local_embeddings[i], stamp, rng) for i in range(LOCAL_OBJECTS)
        ]
        start = time.perf_counter()
        anchoring.process(percepts, view, stamp)
        if frame >= 5:  # the first frames acquire the local objects
            times.append(time.perf_counter() - start)
    return statistics.median(times) * 1e3, len(anchoring)


def memory_of_anchors(count: int, rng: np.random.Generator) -> tuple[float, float, int]:
    """(tracemalloc MB, RSS growth MB, anchors) of an Anchoring acquiring ``count`` far objects.

    A few random objects fall within a few centimetres of one of their class and are (rightly)
    anchored as one, so the anchor count can be slightly below ``count``.
    """
    gc.collect()
    rss_before = resident_mb()
    tracemalloc.start()
    anchoring = new_anchoring()
    acquire_far_anchors(anchoring, count, rng)
    gc.collect()
    traced, _peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    rss_growth = resident_mb() - rss_before
    return traced / 2**20, rss_growth, len(anchoring)


def resident_mb() -> float:
    with open("/proc/self/statm") as statm:
        return int(statm.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


def run(quick: bool = False) -> BenchmarkResult:
    torch.set_num_threads(1)
    rng = np.random.default_rng(0)
    frames = 20 if quick else FRAMES
    memory_count = 1_000 if quick else 10_000
    counts = (100, 1_000) if quick else (100, 1_000, 10_000)
    result = BenchmarkResult(
        "anchoring_scale", "Anchoring per frame as anchors pile up far from the camera",
        f"{LOCAL_OBJECTS} percepts per frame near the camera, plus far anchors 30-230 m away each seen "
        f"{GALLERY_VIEWS} times (full {FEATURE_DIMENSION}-d galleries); rule matcher, depth image "
        f"{INTRINSICS.width}x{INTRINSICS.height} for the occlusion test; median of {frames} frames; one thread. "
        "The baseline is the same scene with the fewest far anchors: the frame loop should not pay for "
        "anchors it cannot see.",
        parameters={"frames": frames, "far_anchors": list(counts), "memory_anchors": memory_count},
    )
    # memory first, while the process has not yet grown its heap: the RSS growth is then meaningful
    traced, rss, anchors = memory_of_anchors(memory_count, rng)
    print(f"  memory for {anchors:,} anchors: {traced:.0f} MB traced, {rss:.0f} MB RSS growth", flush=True)
    target_mb = 300.0 * memory_count / 10_000
    result.figure(f"memory for {anchors:,} anchors (traced)", traced, "MB", target=f"<= {target_mb:.0f} MB",
                  met=traced <= target_mb)
    result.figure(f"memory for {anchors:,} anchors (RSS growth)", rss, "MB", target=f"<= {target_mb:.0f} MB",
                  met=rss <= target_mb)
    costs, rows = {}, []
    for count in counts:
        costs[count], total = frame_cost_ms(count, rng, frames)
        rows.append([count, total, round(costs[count], 3)])
        print(f"  {count:>6} far objects ({total:>6} anchors in all): {costs[count]:6.2f} ms/frame", flush=True)
    spread = max(costs.values()) / min(costs.values())
    result.figure(f"per frame with {counts[-1]:,} far anchors", costs[counts[-1]], "ms/frame",
                  baseline=costs[counts[0]], baseline_name=f"{counts[0]} far anchors",
                  target="within 2x of the baseline", met=spread <= 2.0)
    result.tables.append(Table("per-frame cost vs far anchors", ["far objects", "anchors in all", "ms/frame"], rows))
    result.line_plots.append(LinePlot(
        "anchoring_scale", f"anchoring per frame, {LOCAL_OBJECTS} percepts near the camera", "far anchors",
        "ms per frame", [float(c) for c in counts], {"Anchoring.process": [costs[c] for c in counts]}, log_x=True))
    return result


def main() -> int:
    return script.main(run, __doc__)


if __name__ == "__main__":
    raise SystemExit(main())
