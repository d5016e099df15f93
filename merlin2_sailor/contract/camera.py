"""The pinhole camera: pixels and depth to 3D points, 3D points back to pixels.

Everything is expressed in the ROS optical frame (REP 103): z forward along the optical axis,
x to the right of the image, y down. That is the frame a depth image's pixels live in, so no
axis shuffling happens here; moving into the world frame is the :class:`~.pose.Pose`'s job.

Lens distortion is not modelled: RGB-D drivers publish rectified, registered depth images, and
the detector's boxes are drawn on those same rectified images.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import ConfigurationError, InvalidInputError


@dataclass(frozen=True, slots=True)
class CameraIntrinsics:
    """Pinhole intrinsics of one image stream, in pixels.

    ``width`` and ``height`` belong here because a box, a crop or a frustum test is only
    meaningful against the image size the intrinsics were calibrated for.
    """

    fx: float
    fy: float
    cx: float
    cy: float
    width: int
    height: int

    def __post_init__(self) -> None:
        for name in ("fx", "fy", "cx", "cy"):
            value = getattr(self, name)
            if not math.isfinite(value):
                raise InvalidInputError(f"Camera intrinsic {name} must be finite, got {value}.")
        if self.fx <= 0.0 or self.fy <= 0.0:
            raise InvalidInputError(
                f"Focal lengths must be positive (fx={self.fx}, fy={self.fy}); an all-zero K usually "
                "means the camera driver has no calibration loaded."
            )
        if self.width <= 0 or self.height <= 0:
            raise InvalidInputError(f"Image size must be positive, got {self.width}x{self.height}.")

    @classmethod
    def from_k(cls, k: Sequence[float], width: int, height: int) -> CameraIntrinsics:
        """Build intrinsics from a row-major 3x3 K, as in ``sensor_msgs/CameraInfo.k``."""
        matrix = np.asarray(k, dtype=np.float64).reshape(-1)
        if matrix.shape != (9,):
            raise InvalidInputError(f"K must have 9 values (row-major 3x3), got {matrix.size}.")
        if matrix[1] != 0.0:
            raise InvalidInputError(f"K has a skew term ({matrix[1]}); skewed pixels are not supported.")
        return cls(
            fx=float(matrix[0]),
            fy=float(matrix[4]),
            cx=float(matrix[2]),
            cy=float(matrix[5]),
            width=int(width),
            height=int(height),
        )

    @property
    def k(self) -> np.ndarray:
        """The 3x3 camera matrix."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    def back_project(self, columns: np.ndarray, rows: np.ndarray, depth: np.ndarray) -> np.ndarray:
        """Return the (..., 3) camera-frame points for pixels at (column, row) with z = ``depth``.

        Inputs broadcast against each other, so a row vector of columns and a column vector of
        rows back-project a whole window at once. Pixel coordinates are the pixel centres'
        positions, the same convention as ``cx``/``cy`` in CameraInfo.
        """
        depth = np.asarray(depth, dtype=np.float64)
        x = (np.asarray(columns, dtype=np.float64) - self.cx) / self.fx * depth
        y = (np.asarray(rows, dtype=np.float64) - self.cy) / self.fy * depth
        x, y, z = np.broadcast_arrays(x, y, depth)
        return np.stack((x, y, z), axis=-1)

    def back_project_image(self, depth: np.ndarray) -> np.ndarray:
        """Back-project a whole (H, W) depth image in metres into an organised (H, W, 3) cloud."""
        depth = np.asarray(depth)
        if depth.shape != (self.height, self.width):
            raise InvalidInputError(
                f"Depth image is {depth.shape[1] if depth.ndim > 1 else '?'}x{depth.shape[0]} but the "
                f"camera model is {self.width}x{self.height}."
            )
        columns = np.arange(self.width, dtype=np.float64)[np.newaxis, :]
        rows = np.arange(self.height, dtype=np.float64)[:, np.newaxis]
        return self.back_project(columns, rows, depth)

    def project(self, points_camera: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Project (N, 3) camera-frame points; return ((N, 2) pixel coordinates, (N,) depths).

        Points at or behind the camera get NaN pixel coordinates rather than a mirrored image.
        """
        points = np.asarray(points_camera, dtype=np.float64).reshape(-1, 3)
        depth = points[:, 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            in_front = depth > 0.0
            columns = np.where(in_front, self.fx * points[:, 0] / depth + self.cx, np.nan)
            rows = np.where(in_front, self.fy * points[:, 1] / depth + self.cy, np.nan)
        return np.stack((columns, rows), axis=-1), depth


@dataclass(frozen=True, slots=True)
class FrustumLimits:
    """How far in front of the camera an object must be to count as visible.

    ``near`` and ``far`` bound the range where the depth sensor returns usable values (an
    RGB-D camera sees nothing closer than ~0.2 m and little beyond ~5-8 m); ``margin`` shrinks the
    image by that many pixels on each side, because an object whose centre projects onto the very
    border is usually cut off and missed by the detector.
    """

    near: float = 0.2
    far: float = 8.0
    margin: float = 0.0

    def __post_init__(self) -> None:
        if not (0.0 <= self.near < self.far):
            raise ConfigurationError(f"Frustum limits need 0 <= near < far, got near={self.near}, far={self.far}.")
        if self.margin < 0.0:
            raise ConfigurationError(f"The frustum margin must not be negative, got {self.margin}.")


def points_in_frustum(
    intrinsics: CameraIntrinsics,
    camera_to_world: Pose,
    points_world: np.ndarray,
    limits: FrustumLimits | None = None,
) -> np.ndarray:
    """Return an (N,) bool array: which world points project inside the image, within range.

    The anchoring layer uses this to decide whether a missing anchor *should* have been seen; it
    does not reason about occlusion, which needs the depth image (compare the point's depth with
    the measured depth at its pixel).
    """
    limits = limits or FrustumLimits()
    points_camera = camera_to_world.inverse().transform_points(np.asarray(points_world).reshape(-1, 3))
    pixels, depth = intrinsics.project(points_camera)
    with np.errstate(invalid="ignore"):
        inside = (
            (depth >= limits.near)
            & (depth <= limits.far)
            & (pixels[:, 0] >= -0.5 + limits.margin)
            & (pixels[:, 0] < intrinsics.width - 0.5 - limits.margin)
            & (pixels[:, 1] >= -0.5 + limits.margin)
            & (pixels[:, 1] < intrinsics.height - 0.5 - limits.margin)
        )
    return inside
