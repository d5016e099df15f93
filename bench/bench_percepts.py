"""Milliseconds per frame of the percept hot path: 20 detections, 640x480 RGB-D, one core.

The scene is synthetic but shaped like a busy real one: a noisy back wall, 20 objects of 40-160 px
whose boxes also hold wall pixels, and 5 % of the depth missing. The vectorised estimator is
timed over the whole frame; the baseline, a plain per-pixel Python loop (what the estimate costs
without NumPy), is timed on a subset of the detections and extrapolated by pixel count, which is
how its cost grows. Nothing here is asserted; it prints figures.

Run: python bench/bench_percepts.py [--quick] [--json PATH]
"""

# ruff: noqa: E402 - the thread limits must be set before NumPy and torch are imported
from __future__ import annotations

import os

# One core, as on a robot sharing its CPU: set before NumPy loads its BLAS.
for variable in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[variable] = "1"

import math
import statistics

import numpy as np
from harness import script
from harness.results import BenchmarkResult, Table, median_seconds

from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.perception.box3d import Box3D, Box3DConfig, estimate_boxes_from_depth
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor.perception.percept_generator import PerceptGenerator

WIDTH, HEIGHT, DETECTIONS = 640, 480, 20
REPEATS = 200
BASELINE_DETECTIONS = 3


def busy_scene(seed: int = 0, detections: int = DETECTIONS) -> tuple[np.ndarray, list[BoundingBox2D]]:
    rng = np.random.default_rng(seed)
    depth = (4.0 + rng.normal(0.0, 0.01, (HEIGHT, WIDTH))).astype(np.float32)
    rows, columns = np.mgrid[0:HEIGHT, 0:WIDTH]
    boxes = []
    for _ in range(detections):
        width, height = rng.uniform(40, 160, 2)
        x, y = rng.uniform(0, WIDTH - width), rng.uniform(0, HEIGHT - height)
        inside = ((columns - x - width / 2) / (width / 2)) ** 2 + ((rows - y - height / 2) / (height / 2)) ** 2 <= 1
        object_depth = rng.uniform(0.8, 3.5)
        depth[inside] = np.minimum(depth[inside], object_depth + rng.normal(0.0, 0.02, int(inside.sum())))
        boxes.append(BoundingBox2D.from_corners(x, y, x + width, y + height))
    depth[rng.random((HEIGHT, WIDTH)) < 0.05] = np.nan
    return depth, boxes


def naive_box(
    box: BoundingBox2D, depth: np.ndarray, intrinsics: CameraIntrinsics, pose: Pose, config: Box3DConfig
) -> tuple[list[float], list[float]]:
    """The same estimate written pixel by pixel in Python: the baseline."""
    x_min, y_min, x_max, y_max = box.corners
    c0, c1 = max(0, math.floor(x_min)), min(WIDTH, math.ceil(x_max))
    r0, r1 = max(0, math.floor(y_min)), min(HEIGHT, math.ceil(y_max))
    h, w = r1 - r0, c1 - c0
    mr, mc = int(h * (1 - config.central_region_fraction) / 2), int(w * (1 - config.central_region_fraction) / 2)
    central = [
        float(depth[r, c])
        for r in range(r0 + mr, r1 - mr)
        for c in range(c0 + mc, c1 - mc)
        if config.minimum_depth <= depth[r, c] <= config.maximum_depth
    ]
    centre = statistics.median(central)
    lower, upper = [math.inf] * 3, [-math.inf] * 3
    rotation, translation = pose.rotation.tolist(), pose.translation.tolist()
    for r in range(r0, r1):
        for c in range(c0, c1):
            z = float(depth[r, c])
            if (
                not (config.minimum_depth <= z <= config.maximum_depth)
                or abs(z - centre) > config.depth_band_half_width
            ):
                continue
            point = ((c - intrinsics.cx) / intrinsics.fx * z, (r - intrinsics.cy) / intrinsics.fy * z, z)
            for axis in range(3):
                value = sum(rotation[axis][k] * point[k] for k in range(3)) + translation[axis]
                lower[axis], upper[axis] = min(lower[axis], value), max(upper[axis], value)
    return lower, upper


def frame_pixels(boxes: list[BoundingBox2D]) -> int:
    return sum(
        (min(HEIGHT, math.ceil(b.corners[3])) - max(0, math.floor(b.corners[1])))
        * (min(WIDTH, math.ceil(b.corners[2])) - max(0, math.floor(b.corners[0])))
        for b in boxes
    )


def run(quick: bool = False) -> BenchmarkResult:
    repeats = 30 if quick else REPEATS
    depth, boxes = busy_scene()
    intrinsics = CameraIntrinsics(fx=525.0, fy=525.0, cx=319.5, cy=239.5, width=WIDTH, height=HEIGHT)
    pose = Pose.from_quaternion((0.5, -0.5, 0.5, -0.5), (1.0, 2.0, 0.5))
    config = Box3DConfig()
    image = np.zeros((HEIGHT, WIDTH, 3), np.uint8)
    detections = [Detection(1, "thing", 0.9, box, tracker_id=str(i)) for i, box in enumerate(boxes)]
    box_pixels = frame_pixels(boxes)

    results = estimate_boxes_from_depth(boxes, depth, intrinsics, pose, config)
    assert all(isinstance(r, Box3D) for r in results)
    for index in range(BASELINE_DETECTIONS):  # the two implementations agree
        lower, upper = naive_box(boxes[index], depth, intrinsics, pose, config)
        np.testing.assert_allclose(results[index].size, np.subtract(upper, lower), atol=1e-3)

    vectorised = median_seconds(lambda: estimate_boxes_from_depth(boxes, depth, intrinsics, pose, config), repeats)
    generator = PerceptGenerator()
    percepts = median_seconds(lambda: generator.generate(detections, image, depth, intrinsics, pose, 0.0), repeats)
    subset_pixels = frame_pixels(boxes[:BASELINE_DETECTIONS])
    naive_subset = median_seconds(
        lambda: [naive_box(b, depth, intrinsics, pose, config) for b in boxes[:BASELINE_DETECTIONS]],
        1 if quick else 3, warm_up=0,
    )
    naive_frame = naive_subset * box_pixels / subset_pixels

    result = BenchmarkResult(
        "percepts", "Percept generation per frame",
        f"{WIDTH}x{HEIGHT} RGB-D frame, {DETECTIONS} detections covering {box_pixels} box pixels "
        f"({box_pixels / (WIDTH * HEIGHT):.0%} of the frame), 5 % of the depth missing; one thread. The baseline "
        f"is the same 3D-box estimate written pixel by pixel in Python, timed on {BASELINE_DETECTIONS} detections "
        f"({subset_pixels} px) and scaled by pixel count.",
        parameters={"width": WIDTH, "height": HEIGHT, "detections": DETECTIONS, "repeats": repeats},
    )
    baseline = {"baseline": naive_frame * 1e3, "baseline_name": "per-pixel Python (extrapolated)"}
    result.figure(f"percepts (3D boxes + crops), {DETECTIONS} detections", percepts * 1e3, "ms/frame", **baseline)
    result.figure(f"3D boxes alone, {DETECTIONS} detections", vectorised * 1e3, "ms/frame", **baseline)

    rows = []
    for count in (10, 20, 50):
        depth_n, boxes_n = busy_scene(seed=count, detections=count)
        detections_n = [Detection(1, "thing", 0.9, box, tracker_id=str(i)) for i, box in enumerate(boxes_n)]
        seconds = median_seconds(
            lambda d=detections_n, z=depth_n: generator.generate(d, image, z, intrinsics, pose, 0.0), repeats)
        rows.append([count, frame_pixels(boxes_n), round(seconds * 1e3, 3)])
    result.tables.append(Table("percept generation vs detections per frame", ["detections", "box pixels", "ms/frame"],
                               rows))
    return result


def main() -> int:
    return script.main(run, __doc__)


if __name__ == "__main__":
    raise SystemExit(main())
