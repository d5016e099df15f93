"""Milliseconds per frame of the matching table, batched and gated, against one network call per pair.

Scene: a 20 m x 20 m house with 1,000 anchors of 50 classes (each with a gallery of four
1,280-d appearance embeddings, as EfficientNet-Lite0 gives) and 20 percepts per frame, each near
one anchor, with its embedding already computed (the backbone's own cost is measured by
bench_embedding.py). The matcher is the paper's network (random weights: the cost does not depend
on them). Targets: <= 5 ms per frame on one core; >= 50x faster than the original's one network
call per pair, compared on 20 x 200 pairs. One thread everywhere. Nothing is asserted.

Run: python bench/bench_matching.py
"""

# ruff: noqa: E402 - the thread limits must be set before NumPy and torch are imported
from __future__ import annotations

import os

for variable in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[variable] = "1"

import platform
import statistics
import time
from collections.abc import Callable

import numpy as np
import torch

from merlin2_sailor.anchoring import AnchorIndex, AnchorState, MatchingTableBuilder, Percept
from merlin2_sailor.anchoring.anchor import Anchor
from merlin2_sailor.anchoring.gallery import add_to_gallery, from_bfloat16_bits
from merlin2_sailor.anchoring.matching_network import MatchingNetwork, NetworkMatcher
from merlin2_sailor.anchoring.percept import BoundingBox2D

FEATURE_DIMENSION = 1280
GALLERY_VIEWS = 4
CLASSES = 50
HOUSE_SIDE = 20.0  # metres
PERCEPTS = 20


def machine_description() -> str:
    cpu = "unknown cpu"
    try:
        with open("/proc/cpuinfo") as cpuinfo:
            cpu = next((line.split(":", 1)[1].strip() for line in cpuinfo if line.startswith("model name")), cpu)
    except OSError:
        pass
    return (
        f"machine: {cpu}, {platform.machine()}, {os.cpu_count()} logical CPUs (1 thread used), "
        f"CPython {platform.python_version()}, NumPy {np.__version__}, torch {torch.__version__}"
    )


def house_anchors(
    count: int, rng: np.random.Generator, now: float, unseen_for: float, origin: tuple[float, float] = (0.0, 0.0)
) -> list[Anchor]:
    """``count`` confirmed anchors of 50 classes spread over a house, last seen up to ``unseen_for`` s ago."""
    anchors = []
    for number in range(count):
        position = np.array([*(np.asarray(origin) + rng.uniform(0.0, HOUSE_SIDE, 2)), rng.uniform(0.0, 2.0)])
        anchor = Anchor(
            symbol=f"object_{number}",
            class_name=f"class_{number % CLASSES}",
            position=position,
            size=rng.uniform(0.05, 0.6, 3),
            first_seen=now - unseen_for,
            last_seen=now - rng.uniform(0.0, unseen_for),
            state=AnchorState.CONFIRMED,
            times_seen=GALLERY_VIEWS,
            perceived_position=position.copy(),
        )
        for _ in range(GALLERY_VIEWS):
            view = rng.random(FEATURE_DIMENSION, dtype=np.float32)
            anchor.gallery = add_to_gallery(anchor.gallery, view, GALLERY_VIEWS)
        anchors.append(anchor)
    return anchors


def percepts_near(anchors: list[Anchor], count: int, rng: np.random.Generator, stamp: float) -> list[Percept]:
    """One percept near each of ``count`` random anchors, its embedding close to the anchor's."""
    percepts = []
    for anchor in rng.choice(np.array(anchors, dtype=object), size=count, replace=False):
        noise = rng.normal(scale=0.02, size=FEATURE_DIMENSION).astype(np.float32)
        embedding = from_bfloat16_bits(anchor.gallery[-1]) + noise
        percepts.append(
            Percept(
                class_name=anchor.class_name,
                score=0.8,
                box=BoundingBox2D(320.0, 240.0, 60.0, 60.0),
                position=anchor.position + rng.normal(scale=0.05, size=3),
                size=anchor.size * rng.uniform(0.9, 1.1, 3),
                stamp=stamp,
                embedding=embedding,
            )
        )
    return percepts


def index_of(anchors: list[Anchor]) -> AnchorIndex:
    index = AnchorIndex()
    for anchor in anchors:
        index.add(anchor)
    index.rebuild()
    return index


def median_ms(function: Callable[[], object], repeats: int) -> float:
    function()  # warm-up
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times) * 1e3


def per_pair_ms(matcher: NetworkMatcher, percepts: list[Percept], anchors: list[Anchor]) -> float:
    """The original's way: one network call per (percept, anchor) pair, features already embedded."""
    start = time.perf_counter()
    for percept in percepts:
        for anchor in anchors:
            matcher.score([percept], [anchor])
    return (time.perf_counter() - start) * 1e3


def main() -> None:
    torch.set_num_threads(1)
    torch.manual_seed(0)
    rng = np.random.default_rng(0)
    matcher = NetworkMatcher(MatchingNetwork())
    builder = MatchingTableBuilder(matcher)
    now = 1000.0
    print(machine_description())
    print(f"{PERCEPTS} percepts per frame, {CLASSES} classes over {HOUSE_SIDE:.0f} m x {HOUSE_SIDE:.0f} m, "
          f"galleries of {GALLERY_VIEWS} x {FEATURE_DIMENSION}-d, network matcher (random weights)")

    for unseen_for, label in ((2.0, "anchors seen in the last 2 s"), (60.0, "anchors seen in the last 60 s")):
        anchors = house_anchors(1000, rng, now, unseen_for)
        index = index_of(anchors)
        percepts = percepts_near(anchors, PERCEPTS, rng, now)
        table = builder.build(percepts, index)
        scored = int((~table.gated).sum())
        elapsed = median_ms(lambda p=percepts, i=index: builder.build(p, i), repeats=50)
        print(f"table 20 x 1,000, {label:<30}: {elapsed:6.2f} ms/frame (target <= 5), "
              f"{len(table.anchors)} anchors pass the gate, {scored} pairs scored by the network")

    anchors = house_anchors(200, rng, now, 2.0)
    index = index_of(anchors)
    percepts = percepts_near(anchors, PERCEPTS, rng, now)
    batched = median_ms(lambda: builder.build(percepts, index), repeats=50)
    dense = median_ms(lambda: matcher.score(percepts, anchors), repeats=10)
    one_by_one = per_pair_ms(matcher, percepts, anchors)
    print(f"table 20 x 200, batched and gated:            {batched:8.2f} ms")
    print(f"table 20 x 200, batched, every pair scored:   {dense:8.2f} ms (no gating: batching alone)")
    print(f"table 20 x 200, one network call per pair:    {one_by_one:8.1f} ms (features precomputed)")
    print(f"speed-up, gated batch vs per pair:            {one_by_one / batched:8.0f}x (target >= 50)")
    print(f"speed-up, dense batch vs per pair:            {one_by_one / dense:8.0f}x")
    print("(the original also ran the backbone on both crops of every pair, ~30 ms per crop on one core, "
          f"which would add ~{PERCEPTS * 200 * 2 * 30 / 1e3:.0f} s to the per-pair table)")


if __name__ == "__main__":
    main()
