"""Milliseconds per crop of the appearance embedding, batched against one crop at a time.

Crops come from a real photo (Debian darknet's dog.jpg) at the sizes a detector gives, and go
through the whole path a percept's crop takes: resize to 224 px, ImageNet normalisation, the
frozen EfficientNet-Lite0. One torch thread, as on a robot sharing its CPU. Nothing is asserted.

Run: python bench/bench_embedding.py [number_of_crops]
"""

# ruff: noqa: E402 - the thread limits must be set before NumPy and torch are imported
from __future__ import annotations

import os

for variable in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[variable] = "1"

import platform
import sys
import time
from collections.abc import Callable

import cv2
import numpy as np
import torch

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


def main() -> None:
    torch.set_num_threads(1)
    count = int(sys.argv[1]) if len(sys.argv) > 1 else 32
    crops = crops_from_photo(count)
    print(
        f"machine: {platform.machine()}, CPython {platform.python_version()}, torch {torch.__version__}, "
        f"{os.cpu_count()} logical CPUs, 1 thread; {count} crops of 40-300 px from {PHOTO}"
    )
    for batch_size in (1, 2, 4, 8, 16):
        embedder = CropEmbedder(EmbeddingConfig(batch_size=batch_size))
        embedder.embed(crops[:2])  # warm-up: first calls allocate and pick kernels
        if batch_size == 1:
            elapsed = min(seconds(lambda e=embedder: [e.embed([crop]) for crop in crops]) for _ in range(2))
            label = "one at a time"
        else:
            elapsed = min(seconds(lambda e=embedder: e.embed(crops)) for _ in range(2))
            label = f"batches of {batch_size}"
        print(f"EfficientNet-Lite0, {label:>14}: {elapsed / count * 1e3:6.1f} ms/crop")


if __name__ == "__main__":
    main()
