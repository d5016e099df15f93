"""Detections plus an RGB-D frame and the camera pose become percepts in the world frame.

This is the last step of the perceptual layer: each tracked detection gets its crop and its 3D
box, and becomes the :class:`~merlin2_sailor.contract.percept.Percept` the anchoring layer
consumes. Bad data never escapes as an exception: a frame that cannot be used (mismatched sizes,
a non-finite stamp) drops all its detections, a detection that cannot be measured drops alone,
and every drop carries a reason for the node to log and count.

The depth image must be registered to the colour image (same size, same pixels): that is what
RGB-D drivers publish as ``aligned_depth_to_color`` or ``depth_registered``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.percept import BoundingBox2D, Percept
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.perception.box3d import (
    Box3D,
    Box3DConfig,
    Box3DResult,
    RejectionReason,
    estimate_boxes_from_depth,
    estimate_boxes_from_points,
)
from merlin2_sailor.perception.colour_histogram import object_colour
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor.perception.pixel_window import pixel_window


@dataclass(frozen=True, slots=True)
class PerceptGeneratorConfig:
    """``box3d``: the 3D box thresholds; ``world_frame``: the fixed frame percepts are expressed in
    (the frame ``camera_to_world`` maps into, e.g. "map" or "odom")."""

    box3d: Box3DConfig = field(default_factory=Box3DConfig)
    world_frame: str = "map"

    def __post_init__(self) -> None:
        if not self.world_frame:
            raise ConfigurationError("world_frame must name the fixed frame percepts live in (e.g. 'map').")


@dataclass(frozen=True, slots=True)
class DroppedDetection:
    """A detection that produced no percept: ``reason`` is a stable code, ``detail`` for humans."""

    detection: Detection
    reason: RejectionReason
    detail: str


@dataclass(frozen=True, slots=True)
class PerceptBatch:
    """The percepts of one frame, in detection order, and the detections that were dropped."""

    percepts: tuple[Percept, ...]
    dropped: tuple[DroppedDetection, ...]


class PerceptGenerator:
    """``generate`` (depth image) or ``generate_from_points`` (organised cloud) -> :class:`PerceptBatch`."""

    def __init__(self, config: PerceptGeneratorConfig | None = None) -> None:
        self.config = config or PerceptGeneratorConfig()

    def generate(
        self,
        detections: Sequence[Detection],
        image_rgb: np.ndarray,
        depth_metres: np.ndarray,
        intrinsics: CameraIntrinsics,
        camera_to_world: Pose,
        stamp: float,
    ) -> PerceptBatch:
        """Percepts from a registered depth image in metres (NaN where unknown)."""
        detections = list(detections)
        image = np.asarray(image_rgb)
        depth = np.asarray(depth_metres)
        problem = _frame_problem(image, stamp)
        if problem is None and depth.shape != image.shape[:2]:
            problem = (
                f"depth image {depth.shape[::-1]} and colour image {image.shape[1::-1]} differ in size; "
                "subscribe to the depth registered to the colour camera"
            )
        if problem is None and (intrinsics.width, intrinsics.height) != (image.shape[1], image.shape[0]):
            problem = (
                f"camera info is for {intrinsics.width}x{intrinsics.height} but the image is "
                f"{image.shape[1]}x{image.shape[0]}"
            )
        if problem is not None:
            return _drop_all(detections, problem)
        results = estimate_boxes_from_depth(
            [detection.box for detection in detections],
            depth,
            intrinsics,
            camera_to_world,
            self.config.box3d,
            _masks(detections),
        )
        return self._assemble(detections, results, image, stamp)

    def generate_from_points(
        self,
        detections: Sequence[Detection],
        image_rgb: np.ndarray,
        organised_points: np.ndarray,
        sensor_to_world: Pose,
        stamp: float,
        depth_axis: int | None = 2,
    ) -> PerceptBatch:
        """Percepts from an organised (H, W, 3) point cloud aligned pixel for pixel with the image.

        ``depth_axis`` is the cloud frame's viewing axis (2 for optical frames; see
        :func:`~merlin2_sailor.perception.box3d.estimate_boxes_from_points`).
        """
        detections = list(detections)
        image = np.asarray(image_rgb)
        cloud = np.asarray(organised_points)
        problem = _frame_problem(image, stamp)
        if problem is None and (cloud.ndim != 3 or cloud.shape != (*image.shape[:2], 3)):
            problem = (
                f"point cloud shape {cloud.shape} is not (H, W, 3) for the {image.shape[1]}x{image.shape[0]} image"
            )
        if problem is None and depth_axis not in (0, 1, 2, None):
            problem = f"depth_axis must be 0, 1, 2 or None, got {depth_axis}"
        if problem is not None:
            return _drop_all(detections, problem)
        results = estimate_boxes_from_points(
            [detection.box for detection in detections],
            cloud,
            sensor_to_world,
            self.config.box3d,
            _masks(detections),
            depth_axis,
        )
        return self._assemble(detections, results, image, stamp)

    def _assemble(
        self, detections: list[Detection], results: list[Box3DResult], image: np.ndarray, stamp: float
    ) -> PerceptBatch:
        height, width = image.shape[:2]
        percepts: list[Percept] = []
        dropped: list[DroppedDetection] = []
        for detection, result in zip(detections, results, strict=True):
            if not isinstance(result, Box3D):
                dropped.append(DroppedDetection(detection, result.reason, result.detail))
                continue
            # The 3D box was measured on this same window, so crop and geometry describe the same pixels.
            window = pixel_window(detection.box, width, height)
            if window is None:  # unreachable while box3d and this share pixel_window; kept total
                dropped.append(DroppedDetection(detection, RejectionReason.OUTSIDE_IMAGE, "box covers no pixel"))
                continue
            x_min, y_min, x_max, y_max = detection.box.corners
            crop = image[window.slices]
            percepts.append(
                Percept(
                    class_name=detection.class_name,
                    score=detection.score,
                    box=BoundingBox2D.from_corners(
                        max(x_min, 0.0), max(y_min, 0.0), min(x_max, float(width)), min(y_max, float(height))
                    ),
                    position=result.center,
                    size=result.size,
                    stamp=float(stamp),
                    crop=crop.copy(),
                    tracker_id=detection.tracker_id,
                    class_id=detection.class_id,
                    frame_id=self.config.world_frame,
                    colour=object_colour(crop, result.pixels),
                )
            )
        return PerceptBatch(tuple(percepts), tuple(dropped))


def _frame_problem(image: np.ndarray, stamp: float) -> str | None:
    """What makes a frame unusable as a whole, or None."""
    if image.ndim != 3 or image.shape[2] != 3 or image.dtype != np.uint8:
        return f"colour image must be (H, W, 3) uint8 RGB, got shape {image.shape} and dtype {image.dtype}"
    if image.shape[0] == 0 or image.shape[1] == 0:
        return "colour image is empty"
    if not math.isfinite(stamp):
        return f"frame stamp {stamp} is not finite"
    return None


def _masks(detections: list[Detection]) -> list[np.ndarray | None] | None:
    return [detection.mask for detection in detections] if any(d.mask is not None for d in detections) else None


def _drop_all(detections: list[Detection], detail: str) -> PerceptBatch:
    return PerceptBatch((), tuple(DroppedDetection(d, RejectionReason.INVALID_FRAME, detail) for d in detections))
