"""Depth from a separate depth camera, registered to the colour image pixel for pixel.

An RGB-D sensor such as the Intel SR300 has its depth (infrared) camera a few centimetres from
its colour camera, with its own intrinsics. The percept generator wants depth *registered* to
the colour image (what drivers publish as ``aligned_depth_to_color``), so each depth pixel is
back-projected through the depth camera's model, moved into the colour camera's frame and
projected into the colour image; where several land on one pixel the nearest wins (a z-buffer).

The depth camera's lens model is the inverse Brown-Conrady one RealSense devices calibrate:
the radial and tangential terms are applied to the normalised pixel when back-projecting. A
wider-angle depth camera leaves thin cracks between its samples in the colour image: a pixel
with known depth on two opposite sides takes the nearest depth among its 3x3 neighbours; larger
gaps stay unknown (NaN), their borders untouched.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import ConfigurationError, InvalidInputError


@dataclass(frozen=True, slots=True)
class DepthCamera:
    """A depth camera: pinhole intrinsics (pixels), ``metres_per_unit`` of its raw values and
    ``distortion`` = (k1, k2, p1, p2, k3) of the inverse Brown-Conrady model (empty: none)."""

    fx: float
    fy: float
    cx: float
    cy: float
    metres_per_unit: float
    distortion: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        if self.fx <= 0.0 or self.fy <= 0.0 or self.metres_per_unit <= 0.0:
            raise ConfigurationError("a depth camera needs positive focal lengths and a positive depth unit")
        if self.distortion and len(self.distortion) != 5:
            raise ConfigurationError(f"distortion needs 5 coefficients (k1, k2, p1, p2, k3), got {self.distortion}")

    def back_project(self, raw_depth: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Return ((N, 3) points in the depth camera's optical frame, (N,) flat pixel indices)."""
        raw = np.asarray(raw_depth)
        rows, columns = np.nonzero(raw > 0)
        z = raw[rows, columns].astype(np.float64) * self.metres_per_unit
        x = (columns - self.cx) / self.fx
        y = (rows - self.cy) / self.fy
        if self.distortion:
            k1, k2, p1, p2, k3 = self.distortion
            r2 = x * x + y * y
            radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
            x, y = (x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
                    y * radial + 2.0 * p2 * x * y + p1 * (r2 + 2.0 * y * y))
        return np.stack((x * z, y * z, z), axis=1), rows * raw.shape[1] + columns


def register_depth(
    raw_depth: np.ndarray, depth_camera: DepthCamera, color_from_depth: Pose, color: CameraIntrinsics
) -> np.ndarray:
    """The (H, W) float32 depth in metres of the colour image ``color`` describes, NaN where unknown."""
    if np.asarray(raw_depth).ndim != 2:
        raise InvalidInputError(f"a raw depth frame is an (H, W) array, got shape {np.asarray(raw_depth).shape}")
    points, _ = depth_camera.back_project(raw_depth)
    points = color_from_depth.transform_points(points)
    pixels, z = color.project(points)
    with np.errstate(invalid="ignore"):
        columns = np.rint(pixels[:, 0])
        rows = np.rint(pixels[:, 1])
        inside = (z > 0.0) & (columns >= 0) & (columns < color.width) & (rows >= 0) & (rows < color.height)
    flat = rows[inside].astype(np.intp) * color.width + columns[inside].astype(np.intp)
    nearest = np.full(color.width * color.height, np.inf, dtype=np.float32)
    np.minimum.at(nearest, flat, z[inside].astype(np.float32))
    nearest = nearest.reshape(color.height, color.width)
    neighbours_minimum = cv2.erode(nearest, np.ones((3, 3), np.uint8), borderType=cv2.BORDER_REPLICATE)
    registered = np.where(_cracks(np.isfinite(nearest)), neighbours_minimum, nearest)
    registered[~np.isfinite(registered)] = np.nan
    return registered.astype(np.float32)


def _cracks(known: np.ndarray) -> np.ndarray:
    """Unknown pixels with known neighbours on two opposite sides (across a row, column or diagonal)."""
    height, width = known.shape
    padded = np.pad(known, 1)

    def neighbour(row_step: int, column_step: int) -> np.ndarray:
        return padded[1 + row_step : 1 + row_step + height, 1 + column_step : 1 + column_step + width]

    opposite = (
        (neighbour(0, -1) & neighbour(0, 1)) | (neighbour(-1, 0) & neighbour(1, 0))
        | (neighbour(-1, -1) & neighbour(1, 1)) | (neighbour(-1, 1) & neighbour(1, -1))
    )
    return ~known & opposite
