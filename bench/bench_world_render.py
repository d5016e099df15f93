"""Milliseconds per 640x480 RGB-D frame of the simulated house, on one core; and how often the real
SSD detector finds the rendered objects.

Rendering is timed from every waypoint and from poses along a tour of the house (walls by column,
floor by homography, furniture and objects as z-buffered quads). The baseline is the obvious
renderer: one ray per pixel, intersected in Python with every wall, floor, ceiling and box,
measured on a few rows of the same frames in the same run and extrapolated to the whole image.

The SSD part renders each object from a few viewpoints facing it (0.6 to 2.4 m away) and counts a
hit when SSD-MobileNet-v2 (merlin2_sailor.perception, score >= 0.3) returns the object's class
with an IoU of at least 0.5 against the ground-truth box of its visible part. It is skipped when
the model is not installed. Nothing is asserted; it prints figures.

Run: python bench/bench_world_render.py [--quick] [--json PATH] [--no-ssd]
"""

# ruff: noqa: E402 - the thread limits must be set before NumPy and OpenCV are imported
from __future__ import annotations

import os

for variable in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[variable] = "1"

import math
import time
from collections import defaultdict
from pathlib import Path

import cv2
import numpy as np
from harness import script
from harness.results import BenchmarkResult, Table, median_seconds

from merlin2_sailor.errors import DependencyError
from merlin2_sailor_demos.world import Pose2D, World, load_world
from merlin2_sailor_demos.world.house import House
from merlin2_sailor_demos.world.world import NavigationState

HOUSE_FILE = Path(__file__).resolve().parent.parent / "config" / "worlds" / "house.yaml"
BASELINE_ROWS = (60, 200, 300, 420)  # rows cast per frame by the per-pixel baseline
VIEW_DISTANCES = (0.6, 1.0, 1.6, 2.4)  # metres from the camera to an object, for the SSD views
SSD_SCORE_THRESHOLD = 0.3
IOU_THRESHOLD = 0.5


# --- the baseline: one ray per pixel in Python ------------------------------------------------------


def naive_row(world: World, robot: Pose2D, row: int) -> list[float]:
    """Depth of every pixel of one row, by intersecting each pixel's ray with every surface."""
    camera, house = world.camera, world.house
    pose = camera.optical_pose(robot)
    origin = pose.translation
    boxes = [piece.box for piece in house.furniture] + [item.box for item in world.objects if not item.carried]
    walls = house.wall_array()
    depths = []
    for column in range(camera.width):
        ray = pose.rotation @ np.array([(column - camera.cx) / camera.fx, (row - camera.cy) / camera.fy, 1.0])
        nearest = math.inf
        if ray[2] < 0.0:
            nearest = min(nearest, -origin[2] / ray[2])
        elif ray[2] > 0.0:
            nearest = min(nearest, (house.wall_height - origin[2]) / ray[2])
        for x0, y0, x1, y1 in walls:
            ex, ey = x1 - x0, y1 - y0
            denominator = ray[0] * ey - ray[1] * ex
            if abs(denominator) < 1e-12:
                continue
            rx, ry = x0 - origin[0], y0 - origin[1]
            t = (rx * ey - ry * ex) / denominator
            s = (rx * ray[1] - ry * ray[0]) / denominator
            if 0.0 < t < nearest and 0.0 <= s <= 1.0 and 0.0 <= origin[2] + t * ray[2] <= house.wall_height:
                nearest = t
        for box in boxes:
            low, high = box.minimum, box.maximum
            entry, leave = 0.0, math.inf
            for axis in range(3):
                if abs(ray[axis]) < 1e-12:
                    if not low[axis] <= origin[axis] <= high[axis]:
                        entry, leave = 1.0, 0.0
                    continue
                near_side = (low[axis] - origin[axis]) / ray[axis]
                far_side = (high[axis] - origin[axis]) / ray[axis]
                first, second = min(near_side, far_side), max(near_side, far_side)
                entry, leave = max(entry, first), min(leave, second)
            if entry <= leave and 0.0 < entry < nearest:
                nearest = entry
        depths.append(nearest)  # the ray's z component in the optical frame is 1: t is the depth
    return depths


# --- viewpoints --------------------------------------------------------------------------------------


def tour_poses(world: World, count: int) -> list[Pose2D]:
    """``count`` true poses spread over a drive through every waypoint."""
    poses = []
    for waypoint in (*world.house.waypoints[1:], world.house.waypoints[0]):
        world.navigate_to(waypoint.pose.x, waypoint.pose.y, waypoint.pose.yaw)
        while world.navigation.state is NavigationState.ACTIVE:
            world.step(0.25)
            poses.append(world.true_pose)
    step = max(len(poses) // count, 1)
    return poses[::step][:count]


def views_of(world: World, index: int, house: House) -> list[tuple[float, Pose2D]]:
    """(distance, robot pose) whose camera faces object ``index`` from each of VIEW_DISTANCES, where it can stand."""
    item = world.objects[index]
    room = house.room_at(*item.position[:2])
    views = []
    for distance in VIEW_DISTANCES:
        for angle in np.linspace(-math.pi, math.pi, 24, endpoint=False):
            back = distance + world.camera.mount_forward
            x, y = item.position[0] - back * math.cos(angle), item.position[1] - back * math.sin(angle)
            if room is None or not room.contains(x, y, -0.3) or not world.graph.segment_clear((x, y), (x, y)):
                continue
            views.append((distance, Pose2D(x, y, float(angle))))
            break
    return views


def iou(first: tuple[float, ...], second: tuple[float, ...]) -> float:
    width = min(first[2], second[2]) - max(first[0], second[0])
    height = min(first[3], second[3]) - max(first[1], second[1])
    if width <= 0 or height <= 0:
        return 0.0
    union = ((first[2] - first[0]) * (first[3] - first[1]) + (second[2] - second[0]) * (second[3] - second[1])
             - width * height)
    return width * height / union


# --- the benchmark -----------------------------------------------------------------------------------


def run(quick: bool = False, no_ssd: bool = False) -> BenchmarkResult:
    cv2.setNumThreads(1)
    world = World(load_world(HOUSE_FILE), seed=0)
    house = world.house
    poses = [waypoint.pose for waypoint in house.waypoints] + tour_poses(world, 8 if quick else 24)
    world.navigation = None
    repeats = 3 if quick else 10
    renderer = world.renderer
    for pose in poses[:2]:
        renderer.render(pose, world.objects)  # load every texture before timing
    render_seconds = [median_seconds(lambda p=pose: renderer.render(p, world.objects), repeats) for pose in poses]
    frame_seconds = []
    for pose in poses:
        world.true_pose = pose
        frame_seconds.append(median_seconds(world.render, repeats))
    detect_seconds = median_seconds(lambda: world.detect(world.render()), repeats) - median_seconds(world.render,
                                                                                                   repeats)
    baseline_poses = poses[:: max(len(poses) // (2 if quick else 4), 1)]
    baseline_row_seconds = []
    for pose in baseline_poses:
        started = time.perf_counter()
        for row in BASELINE_ROWS:
            naive_row(world, pose, row)
        baseline_row_seconds.append((time.perf_counter() - started) / len(BASELINE_ROWS))
    baseline_frame = float(np.median(baseline_row_seconds)) * world.camera.height

    result = BenchmarkResult(
        "world_render", "Simulated house: rendering per frame, and SSD on rendered objects",
        f"640x480 colour + depth of config/worlds/house.yaml ({len(house.walls)} walls, {len(house.furniture)} "
        f"pieces of furniture, {len(world.objects)} objects) from {len(poses)} poses (the waypoints and a tour); "
        f"one thread. The baseline casts one ray per pixel in Python against every surface (depth only, no "
        f"texture), timed on {len(BASELINE_ROWS)} rows of {len(baseline_poses)} of the frames and scaled to "
        f"{world.camera.height} rows.",
        parameters={"poses": len(poses), "repeats": repeats, "objects": len(world.objects)},
    )
    baseline = {"baseline": baseline_frame * 1e3, "baseline_name": "per-pixel ray casting in Python (extrapolated)"}
    result.figure("render (colour, true depth, instance ids), median", float(np.median(render_seconds)) * 1e3,
                  "ms/frame", target="<= 25 ms", met=float(np.median(render_seconds)) <= 0.025, **baseline)
    result.figure("render, slowest pose", float(np.max(render_seconds)) * 1e3, "ms/frame", **baseline)
    result.figure("frame with depth-sensor noise, median", float(np.median(frame_seconds)) * 1e3, "ms/frame",
                  **baseline)
    result.figure("ground-truth detections per frame", max(detect_seconds, 0.0) * 1e3, "ms/frame")
    result.tables.append(Table(
        "render time by pose", ["pose", "x", "y", "yaw (deg)", "ms/frame"],
        [[name, round(p.x, 2), round(p.y, 2), round(math.degrees(p.yaw)), round(s * 1e3, 2)]
         for name, p, s in zip([w.name for w in house.waypoints] + [f"tour {i}" for i in range(len(poses))],
                               poses, render_seconds, strict=False)]))
    if not no_ssd:
        _measure_ssd(world, result, quick)
    return result


def _measure_ssd(world: World, result: BenchmarkResult, quick: bool) -> None:
    try:
        from merlin2_sailor.perception.ssd_mobilenet import SsdMobileNetConfig, SsdMobileNetDetector

        detector = SsdMobileNetDetector(SsdMobileNetConfig(score_threshold=SSD_SCORE_THRESHOLD))
    except DependencyError as error:
        result.notes.append(f"SSD part skipped: {error}")
        return
    hits: dict[str, list[bool]] = defaultdict(list)
    by_distance: dict[float, list[bool]] = defaultdict(list)
    pixels: dict[float, list[float]] = defaultdict(list)
    located: list[bool] = []
    misnamed: dict[str, int] = defaultdict(int)
    objects = world.objects if not quick else world.objects[::3]
    for item in objects:
        index = world.objects.index(item)
        for distance, pose in views_of(world, index, world.house):
            world.true_pose = pose
            frame = world.render()
            visible = {seen.index: seen for seen in world.visible_objects(frame)}
            if index not in visible or visible[index].fraction < 0.5:
                continue
            truth = visible[index].box.corners
            found = detector.detect(frame.color)
            overlapping = [d for d in found if iou(d.box.corners, truth) >= IOU_THRESHOLD]
            hit = any(d.class_name == item.class_name for d in overlapping)
            hits[item.class_name].append(hit)
            by_distance[distance].append(hit)
            pixels[distance].append(max(truth[2] - truth[0], truth[3] - truth[1]))
            located.append(bool(overlapping))
            if overlapping and not hit:
                misnamed[max(overlapping, key=lambda d: d.score).class_name] += 1
    views = sum(len(values) for values in hits.values())
    if not views:
        result.notes.append("SSD part: no usable views")
        return
    rate = sum(sum(values) for values in hits.values()) / views
    result.figure(f"SSD hit rate on rendered objects ({views} views, 0.6-2.4 m)", rate * 100.0, "%", better="higher")
    result.figure("SSD boxes any class on the object (IoU >= 0.5)", float(np.mean(located)) * 100.0, "%",
                  better="higher")
    result.tables.append(Table(
        "SSD-MobileNet-v2 on rendered objects, by class (score >= 0.3, IoU >= 0.5)", ["class", "views", "hits", "%"],
        [[name, len(values), sum(values), round(100.0 * sum(values) / len(values))]
         for name, values in sorted(hits.items())]))
    result.tables.append(Table(
        "SSD hit rate by viewing distance", ["distance (m)", "views", "median box side (px)", "%"],
        [[distance, len(values), round(float(np.median(pixels[distance]))), round(100.0 * sum(values) / len(values))]
         for distance, values in sorted(by_distance.items())]))
    if misnamed:
        result.notes.append("objects found under another class: " + ", ".join(
            f"{name} x{count}" for name, count in sorted(misnamed.items(), key=lambda kv: -kv[1])))


def main() -> int:
    return script.main(run, __doc__, extend=lambda parser: parser.add_argument(
        "--no-ssd", action="store_true", help="skip the SSD hit-rate measurement"))


if __name__ == "__main__":
    raise SystemExit(main())
