"""From a 2D detection and depth to an object's 3D box in the world frame (the hot path).

For each detection the pixels inside its 2D box (or its mask) are read; pixels without depth are
ignored. A robust depth for the object is the median over the central part of the box, where the
object is most likely to be rather than the background around it. Only pixels within a depth band
around that value are kept (SAILOR's paper uses 0.2 m), which discards the background and
foreground the rectangular box also contains. Those pixels are back-projected, moved into the
world frame with the camera pose at the image's timestamp, and their per-axis minimum and maximum
give the box: its size is the extent along the world axes and its centre the middle of that extent.

Detections that cannot be measured are rejected with a reason instead of raising, because a bad
box is ordinary data in a robot's life: the node logs the reason and drops the detection. Frame
level inconsistencies (a depth image whose size does not match the camera model) are caller bugs
and raise :class:`~merlin2_sailor.errors.InvalidInputError`.

Each detection costs a handful of NumPy passes over its own window, never over the whole image,
so 20 detections covering 60 % of a 640x480 frame take under 2 ms on one core
(``bench/bench_percepts.py``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from enum import StrEnum

import numpy as np

from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import ConfigurationError, InvalidInputError
from merlin2_sailor.perception.pixel_window import PixelWindow, pixel_window


@dataclass(frozen=True, slots=True)
class Box3DConfig:
    """Thresholds of the 3D box estimate.

    ``depth_band_half_width``: points farther than this (metres) from the object's robust depth,
    towards or away from the camera, are taken as background or occluders (paper: 0.2 m).
    ``central_region_fraction``: the fraction of the box's width and height, around its centre,
    whose median depth is taken as the object's depth.
    ``minimum_valid_pixels``: fewer usable depth pixels than this in the box, or in the band, and
    the detection is rejected: a box from a handful of pixels is noise, not an object.
    ``minimum_central_pixels``: below this many usable pixels in the central region (a ring-shaped
    object, a hole in the depth), the median is taken over the whole box instead.
    ``minimum_depth`` / ``maximum_depth``: the sensor's trustworthy range in metres; readings
    outside it are treated as missing.
    ``maximum_median_samples``: the robust depth is the median of at most this many regularly
    spaced pixels, which bounds its cost on large boxes without changing it measurably.
    ``minimum_depth_coverage``: the fraction of the central region (inside the mask, if any) that
    must have usable depth. Below it the object itself is mostly unmeasured (beyond the sensor's
    range, seen through a doorway) and the few readings there belong to something else, such as
    the door frame: the detection is rejected rather than anchored on the wall.
    ``mask_depth_gap``: with an instance mask, the object's points are the run of depths around
    the median with no gap wider than this (metres) instead of the fixed band, so that a wide
    object seen at a slant is kept whole.
    """

    depth_band_half_width: float = 0.2
    central_region_fraction: float = 0.5
    minimum_valid_pixels: int = 20
    minimum_central_pixels: int = 5
    minimum_depth: float = 0.1
    maximum_depth: float = 20.0
    maximum_median_samples: int = 4096
    minimum_depth_coverage: float = 0.25
    mask_depth_gap: float = 0.1

    def __post_init__(self) -> None:
        if not (math.isfinite(self.depth_band_half_width) and self.depth_band_half_width > 0.0):
            raise ConfigurationError(
                f"depth_band_half_width must be a positive number of metres, got {self.depth_band_half_width}."
            )
        if not (math.isfinite(self.mask_depth_gap) and self.mask_depth_gap > 0.0):
            raise ConfigurationError(f"mask_depth_gap must be a positive number of metres, got {self.mask_depth_gap}.")
        if not (0.0 <= self.minimum_depth_coverage <= 1.0):
            raise ConfigurationError(f"minimum_depth_coverage must be in [0, 1], got {self.minimum_depth_coverage}.")
        if not (0.0 < self.central_region_fraction <= 1.0):
            raise ConfigurationError(f"central_region_fraction must be in (0, 1], got {self.central_region_fraction}.")
        for name in ("minimum_valid_pixels", "minimum_central_pixels", "maximum_median_samples"):
            if getattr(self, name) < 1:
                raise ConfigurationError(f"{name} must be at least 1, got {getattr(self, name)}.")
        if not (0.0 <= self.minimum_depth < self.maximum_depth):
            raise ConfigurationError(
                f"Depth range needs 0 <= minimum_depth < maximum_depth, got {self.minimum_depth} and "
                f"{self.maximum_depth}."
            )


class RejectionReason(StrEnum):
    """Why a detection produced no 3D box; the value is a stable string for logs and metrics."""

    INVALID_BOX = "invalid_box"
    OUTSIDE_IMAGE = "outside_image"
    INVALID_MASK = "invalid_mask"
    TOO_FEW_DEPTH_PIXELS = "too_few_depth_pixels"
    TOO_FEW_PIXELS_IN_BAND = "too_few_pixels_in_band"
    DEPTH_MOSTLY_MISSING = "depth_mostly_missing"
    INVALID_FRAME = "invalid_frame"


@dataclass(frozen=True, slots=True)
class Rejection:
    """Detection ``index`` (its position in the input) was dropped, and why."""

    index: int
    reason: RejectionReason
    detail: str


@dataclass(frozen=True, slots=True, eq=False)
class Box3D:
    """The 3D box of detection ``index``, axis-aligned in the world frame.

    ``center`` and ``size`` are in metres in the world frame; ``center_depth`` is the robust
    camera-frame depth of the object (useful for occlusion tests and logs); ``point_count`` is
    how many depth pixels the box was built from; ``pixels`` marks them, (h, w) boolean over the
    detection's pixel window: the object's own pixels, without the background the 2D box also
    covers (what the object's colour is read from, see the percept generator).
    """

    index: int
    center: np.ndarray
    size: np.ndarray
    center_depth: float
    point_count: int
    pixels: np.ndarray


Box3DResult = Box3D | Rejection

# Builds the (3, N) sensor-frame points of the pixels a boolean mask of the window selects; (3, N)
# rather than (N, 3) so the per-axis minimum and maximum run over contiguous rows.
_PointBuilder = Callable[[PixelWindow, np.ndarray], np.ndarray]


def estimate_boxes_from_depth(
    boxes: Sequence[BoundingBox2D],
    depth_metres: np.ndarray,
    intrinsics: CameraIntrinsics,
    camera_to_world: Pose,
    config: Box3DConfig | None = None,
    masks: Sequence[np.ndarray | None] | None = None,
) -> list[Box3DResult]:
    """Estimate the world-frame 3D box of each 2D box from a depth image in metres.

    ``depth_metres`` is (H, W) float with NaN, zero or inf where there is no depth (see
    :func:`~merlin2_sailor.perception.depth.depth_to_metres`). ``masks``, when given, holds
    one (H, W) boolean instance mask or None per box; a mask restricts the pixels to the object's
    silhouette. The result has one entry per box, in order: a :class:`Box3D` or a
    :class:`Rejection`.
    """
    depth = np.asarray(depth_metres)
    if depth.shape != (intrinsics.height, intrinsics.width):
        raise InvalidInputError(
            f"Depth image shape {depth.shape} does not match the camera model "
            f"({intrinsics.height}, {intrinsics.width}); use the CameraInfo of the depth stream."
        )

    # Per-column and per-row ray slopes, computed once per frame in float32: back-projection then
    # costs one table look-up and one multiplication per pixel and coordinate.
    column_slopes = ((np.arange(intrinsics.width) - intrinsics.cx) / intrinsics.fx).astype(np.float32)
    row_slopes = ((np.arange(intrinsics.height) - intrinsics.cy) / intrinsics.fy).astype(np.float32)

    def camera_points(window: PixelWindow, selected: np.ndarray) -> np.ndarray:
        # Multiplying the whole window and then compacting is about twice as fast as gathering
        # the selected pixels' coordinates first: dense products vectorise, index arrays do not.
        z = depth[window.slices]
        points = np.empty((3, int(np.count_nonzero(selected))), dtype=np.float32)
        points[0] = (z * column_slopes[window.column_start : window.column_stop])[selected]
        points[1] = (z * row_slopes[window.row_start : window.row_stop, np.newaxis])[selected]
        points[2] = z[selected]
        return points

    return _estimate_boxes(boxes, depth, camera_points, camera_to_world, config or Box3DConfig(), masks)


def estimate_boxes_from_points(
    boxes: Sequence[BoundingBox2D],
    organised_points: np.ndarray,
    sensor_to_world: Pose,
    config: Box3DConfig | None = None,
    masks: Sequence[np.ndarray | None] | None = None,
    depth_axis: int | None = 2,
) -> list[Box3DResult]:
    """Estimate 3D boxes from an organised point cloud, (H, W, 3) points aligned with the image.

    The points are in the cloud's own frame, which ``sensor_to_world`` maps into the world; NaN
    or inf points mean "no measurement". ``depth_axis`` names the coordinate the depth band
    applies to: 2 (z) for an optical frame, as clouds from a depth image are, which gives exactly
    the result of :func:`estimate_boxes_from_depth`; 0 for a ``camera_link``-style frame with x
    forward; None for the distance from the sensor, when no axis points along the view (the
    band then trims the edges of wide objects seen off-axis, whose distance grows with the angle).
    """
    cloud = np.asarray(organised_points)
    if cloud.ndim != 3 or cloud.shape[2] != 3:
        raise InvalidInputError(f"An organised point cloud must be (H, W, 3), got shape {cloud.shape}.")
    if depth_axis is None:
        with np.errstate(invalid="ignore"):
            range_image = np.sqrt(np.einsum("hwc,hwc->hw", cloud, cloud, dtype=np.float64))
    elif depth_axis in (0, 1, 2):
        range_image = cloud[:, :, depth_axis]
    else:
        raise InvalidInputError(f"depth_axis must be 0, 1, 2 or None, got {depth_axis}.")

    def sensor_points(window: PixelWindow, selected: np.ndarray) -> np.ndarray:
        return cloud[window.slices][selected].astype(np.float32, copy=False).T

    return _estimate_boxes(boxes, range_image, sensor_points, sensor_to_world, config or Box3DConfig(), masks)


def _estimate_boxes(
    boxes: Sequence[BoundingBox2D],
    range_image: np.ndarray,
    build_points: _PointBuilder,
    sensor_to_world: Pose,
    config: Box3DConfig,
    masks: Sequence[np.ndarray | None] | None,
) -> list[Box3DResult]:
    height, width = range_image.shape
    if masks is not None and len(masks) != len(boxes):
        raise InvalidInputError(f"Got {len(masks)} masks for {len(boxes)} boxes; pass one mask (or None) per box.")
    results: list[Box3DResult] = []
    for index, box in enumerate(boxes):
        mask = None if masks is None else masks[index]
        results.append(
            _estimate_one(index, box, mask, range_image, width, height, build_points, sensor_to_world, config)
        )
    return results


def _estimate_one(
    index: int,
    box: BoundingBox2D,
    mask: np.ndarray | None,
    range_image: np.ndarray,
    width: int,
    height: int,
    build_points: _PointBuilder,
    sensor_to_world: Pose,
    config: Box3DConfig,
) -> Box3DResult:
    x_min, y_min, x_max, y_max = box.corners
    if not all(math.isfinite(value) for value in (x_min, y_min, x_max, y_max)) or x_max <= x_min or y_max <= y_min:
        return Rejection(
            index, RejectionReason.INVALID_BOX, f"box corners {box.corners} are not a finite, non-empty box"
        )
    window = pixel_window(box, width, height)
    if window is None:
        return Rejection(
            index, RejectionReason.OUTSIDE_IMAGE, f"box corners {box.corners} lie outside the {width}x{height} image"
        )

    window_range = range_image[window.slices]
    window_mask: np.ndarray | None = None
    if mask is not None:
        mask = np.asarray(mask)
        if mask.shape != (height, width):
            return Rejection(
                index,
                RejectionReason.INVALID_MASK,
                f"mask shape {mask.shape} differs from the image ({height}, {width})",
            )
        window_mask = mask[window.slices].astype(bool, copy=False)

    center_depth, coverage = _robust_depth(window_range, window_mask, config)
    if center_depth is None:
        return _too_few_pixels(index, window_range, window_mask, config, band_count=0, center_depth=math.nan)
    if coverage < config.minimum_depth_coverage:
        too_few = _too_few_pixels(index, window_range, window_mask, config, band_count=0, center_depth=center_depth)
        if too_few.reason is RejectionReason.TOO_FEW_DEPTH_PIXELS:
            return too_few  # the more specific reason
        return Rejection(
            index,
            RejectionReason.DEPTH_MOSTLY_MISSING,
            f"{100 * coverage:.0f}% of the box's centre has usable depth, under "
            f"{100 * config.minimum_depth_coverage:.0f}%: the object is likely beyond the sensor's range",
        )
    # The band and the sensor range are both intervals, so one pair of comparisons does both, and
    # comparisons with NaN are False, so it also discards missing readings.
    if window_mask is not None:
        band_low, band_high = _mask_surface_interval(window_range, window_mask, center_depth, config)
    else:
        band_low = max(center_depth - config.depth_band_half_width, config.minimum_depth)
        band_high = min(center_depth + config.depth_band_half_width, config.maximum_depth)
    band = (window_range >= band_low) & (window_range <= band_high)
    if window_mask is not None:
        band &= window_mask
    band_count = int(np.count_nonzero(band))
    if band_count < config.minimum_valid_pixels:
        return _too_few_pixels(index, window_range, window_mask, config, band_count, center_depth)

    # min/max of (R p + t) is min/max of (R p) plus t, so the translation is added once at the end.
    rotated = sensor_to_world.rotation.astype(np.float32) @ build_points(window, band)
    lower = rotated.min(axis=1).astype(np.float64)
    upper = rotated.max(axis=1).astype(np.float64)
    return Box3D(
        index=index,
        center=(lower + upper) / 2.0 + sensor_to_world.translation,
        size=upper - lower,
        center_depth=center_depth,
        point_count=band_count,
        pixels=band,
    )


def _mask_surface_interval(
    window_range: np.ndarray, window_mask: np.ndarray, center_depth: float, config: Box3DConfig
) -> tuple[float, float]:
    """The depth interval of the object's surface under a mask: the run of depths around the
    median with no gap wider than ``mask_depth_gap``.

    A mask already leaves out the floor and the table, so the fixed band is not needed against
    them, and it would cut a wide object seen at a slant (a television's far end is a metre
    deeper than its near end). What a mask's edge still catches (a sliver of wall behind) lies
    beyond a gap in depth, and stays out.
    """
    stride = max(1, math.ceil(math.sqrt(window_range.size / config.maximum_median_samples)))
    region = (slice(None, None, stride),) * 2
    depths = np.sort(_usable_values(window_range, window_mask, region, config))
    if depths.size < 2:
        return (max(center_depth - config.depth_band_half_width, config.minimum_depth),
                min(center_depth + config.depth_band_half_width, config.maximum_depth))
    # Sampling every stride-th pixel makes the steps between the depths of a slanted surface
    # stride times larger: the gap that separates two surfaces grows with it.
    gap = config.mask_depth_gap * stride
    breaks = np.flatnonzero(np.diff(depths) > gap)  # a break lies after depths[i]
    middle = int(np.searchsorted(depths, center_depth))
    below = breaks[breaks < middle]
    above = breaks[breaks >= middle]
    low = depths[below[-1] + 1] if below.size else depths[0]
    high = depths[above[0]] if above.size else depths[-1]
    # The sample skips pixels: widen by one gap so the skipped ones of the same surface are kept.
    return max(float(low) - gap, config.minimum_depth), min(float(high) + gap, config.maximum_depth)


def _usable(values: np.ndarray, config: Box3DConfig) -> np.ndarray:
    """Which range readings count as measurements (NaN compares False, so it is excluded too)."""
    return (values >= config.minimum_depth) & (values <= config.maximum_depth)


def _too_few_pixels(
    index: int,
    window_range: np.ndarray,
    window_mask: np.ndarray | None,
    config: Box3DConfig,
    band_count: int,
    center_depth: float,
) -> Rejection:
    """Tell "the box has almost no depth" apart from "the depth is there but scattered".

    Counting every usable pixel costs a pass over the window, so it is done only here, on the
    rejection path, rather than for every detection.
    """
    usable = _usable(window_range, config)
    if window_mask is not None:
        usable &= window_mask
    usable_count = int(np.count_nonzero(usable))
    if usable_count < config.minimum_valid_pixels:
        return Rejection(
            index,
            RejectionReason.TOO_FEW_DEPTH_PIXELS,
            f"{usable_count} pixels with usable depth, fewer than {config.minimum_valid_pixels}",
        )
    return Rejection(
        index,
        RejectionReason.TOO_FEW_PIXELS_IN_BAND,
        f"{band_count} of {usable_count} depth pixels lie within {config.depth_band_half_width} m of the "
        f"object's depth {center_depth:.2f} m, fewer than {config.minimum_valid_pixels}",
    )


def _central_region(window_shape: tuple[int, ...], config: Box3DConfig) -> tuple[slice, slice]:
    """The central part of a window, sampled on a grid of at most ``maximum_median_samples`` pixels."""
    window_height, window_width = window_shape
    margin_rows = int(window_height * (1.0 - config.central_region_fraction) / 2.0)
    margin_columns = int(window_width * (1.0 - config.central_region_fraction) / 2.0)
    central_pixels = (window_height - 2 * margin_rows) * (window_width - 2 * margin_columns)
    stride = max(1, math.ceil(math.sqrt(central_pixels / config.maximum_median_samples)))
    return (
        slice(margin_rows, window_height - margin_rows, stride),
        slice(margin_columns, window_width - margin_columns, stride),
    )


def _robust_depth(
    window_range: np.ndarray, window_mask: np.ndarray | None, config: Box3DConfig
) -> tuple[float | None, float]:
    """Median depth of the central region, or of the whole box when the centre has too few
    readings; and the central region's coverage: the fraction of its pixels (inside the mask, if
    any) with usable depth, read from the same sample.

    Large regions are sampled on a regular grid of at most ``maximum_median_samples`` pixels: the
    median of a few thousand pixels of one surface is the same to within millimetres, and the
    selection it needs grows with the number of pixels. The depth is None when the box has no
    usable depth at all.
    """
    central = _central_region(window_range.shape, config)
    values = window_range[central]
    usable = _usable(values, config)
    if window_mask is None:
        coverage = float(np.count_nonzero(usable)) / max(usable.size, 1)
    else:
        inside = window_mask[central]
        usable &= inside
        inside_count = int(np.count_nonzero(inside))
        # A mask that misses the centre says nothing about coverage there; the pixel counts decide.
        coverage = float(np.count_nonzero(usable)) / inside_count if inside_count else 1.0
    central_values = values[usable]
    if central_values.size >= config.minimum_central_pixels:
        return float(np.median(central_values, overwrite_input=True)), coverage
    stride = max(1, math.ceil(math.sqrt(window_range.size / config.maximum_median_samples)))
    whole_values = _usable_values(window_range, window_mask, (slice(None, None, stride),) * 2, config)
    if whole_values.size == 0 and stride > 1:  # the regular sample missed the few usable pixels
        whole_values = _usable_values(window_range, window_mask, (slice(None), slice(None)), config)
    if whole_values.size == 0:
        return None, coverage
    return float(np.median(whole_values, overwrite_input=True)), coverage


def _usable_values(
    window_range: np.ndarray,
    window_mask: np.ndarray | None,
    region: tuple[slice, slice],
    config: Box3DConfig,
) -> np.ndarray:
    """A copy of the usable range readings of one region of the window (inside the mask, if any)."""
    values = window_range[region]
    usable = _usable(values, config)
    if window_mask is not None:
        usable &= window_mask[region]
    return values[usable]
