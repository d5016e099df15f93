"""Milliseconds per crop of the appearance embedding, batched against one crop at a time.

Crops come from a real photo (Debian darknet's dog.jpg) at the sizes a detector gives, and go
through the whole path a percept's crop takes: resize to 224 px, ImageNet normalisation, the
frozen EfficientNet-Lite0. One torch thread, as on a robot sharing its CPU. Nothing is asserted.
This is torch's batching study; the runtime the nodes use by default (OpenVINO) is measured
against torch by ``bench_inference.py``.

Run: python bench/bench_embedding.py [number_of_crops] [--quick] [--json PATH]
"""

# ruff: noqa: E402 - the thread limits must be set before NumPy and torch are imported
from __future__ import annotations

import os

for variable in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[variable] = "1"

import argparse
import time
from collections.abc import Callable

import cv2
import numpy as np
import torch
from harness import script
from harness.results import BenchmarkResult, Table

from merlin2_sailor.inference.settings import InferenceSettings
from merlin2_sailor.perception.embedding import CropEmbedder, EmbeddingConfig

PHOTO = "/usr/share/darknet/data/dog.jpg"


def crops_from_photo(count: int, seed: int = 0) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    bgr = cv2.imread(PHOTO)
    image = cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB) if bgr is not None else rng.integers(0, 255, (576, 768, 3), np.uint8)
    height, width = image.shape[:2]
    crops = []
    for _ in range(count):
        crop_width, crop_height = rng.integers(40, 300, 2)
        x, y = rng.integers(0, width - crop_width), rng.integers(0, height - crop_height)
        crops.append(image[y : y + crop_height, x : x + crop_width])
    return crops


def seconds(function: Callable[[], object]) -> float:
    start = time.perf_counter()
    function()
    return time.perf_counter() - start


def run(quick: bool = False, crops: int = 0) -> BenchmarkResult:
    torch.set_num_threads(1)
    count = crops or (8 if quick else 32)
    batch_sizes = (1, 4, 8) if quick else (1, 2, 4, 8, 16)
    repeats = 2
    images = crops_from_photo(count)
    default_batch = EmbeddingConfig().batch_size
    result = BenchmarkResult(
        "embedding", "Crop embedding per crop",
        f"{count} crops of 40-300 px from {PHOTO}, through the whole path of a percept's crop (resize to 224 px, "
        f"ImageNet normalisation, frozen EfficientNet-Lite0); torch {torch.__version__}, one thread. Baseline: one "
        f"crop per forward pass. Best of {repeats} passes over the crops.",
        parameters={"crops": count, "batch_sizes": list(batch_sizes), "threads": 1},
    )
    per_crop = {}
    for batch_size in batch_sizes:
        embedder = CropEmbedder(EmbeddingConfig(batch_size=batch_size, inference=InferenceSettings(runtime="native")))
        embedder.embed(images[:2])  # warm-up: first calls allocate and pick kernels
        if batch_size == 1:
            elapsed = min(seconds(lambda e=embedder: [e.embed([crop]) for crop in images]) for _ in range(repeats))
        else:
            elapsed = min(seconds(lambda e=embedder: e.embed(images)) for _ in range(repeats))
        per_crop[batch_size] = elapsed / count * 1e3
        print(f"  batch size {batch_size:>2}: {per_crop[batch_size]:6.1f} ms/crop", flush=True)
    one_at_a_time = {"baseline": per_crop[1], "baseline_name": "one crop at a time"}
    if default_batch in per_crop:
        result.figure(f"batches of {default_batch} (the node's default)", per_crop[default_batch], "ms/crop",
                      **one_at_a_time)
    best = min((size for size in per_crop if size > 1), key=per_crop.__getitem__)
    if best != default_batch:
            result.figure(f"best batch size ({best})", per_crop[best], "ms/crop", **one_at_a_time)
    result.tables.append(Table("ms per crop by batch size", ["batch size", "ms/crop"],
                               [[size, round(value, 2)] for size, value in per_crop.items()]))
    return result


def main() -> int:
    def extend(parser: argparse.ArgumentParser) -> None:
        parser.add_argument("crops", nargs="?", type=int, default=0, help="number of crops (default 32, quick 8)")

    return script.main(run, __doc__, extend=extend)


if __name__ == "__main__":
    raise SystemExit(main())
