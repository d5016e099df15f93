"""Depth for a fixed monocular camera looking down at flat ground.

A camera at ``height`` metres above a flat ground, pitched ``pitch`` degrees below the horizon,
sees each pixel below the horizon hit the ground at a known distance: the pixel's viewing ray,
turned into the world frame, meets the plane z = 0. That gives a depth image of the empty scene.

A person (or any object standing on the ground) is taken as an upright board facing the camera,
standing where the bottom centre of its detection box (the foot point) meets the ground. Every
pixel of the box gets the depth of its ray's hit with that board, so the percept generator's
3D box is the object's upright extent above its foot point, and nearer objects hide farther ones.
Distances are only as good as the model: a flat ground, the stated height and pitch, and the foot
point on the ground (a box cut off at the image border or a person on a step are wrong).

World frame: x forward along the camera's heading, y left, z up, origin on the ground below the
camera (REP 103). Pixel centres sit at integer coordinates (as in CameraInfo); detection boxes
are in edge coordinates (the image spans [0, width]), so a box edge x is pixel coordinate x - 0.5.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor_demos.replay.source import WORLD_FROM_LEVEL_OPTICAL


@dataclass(frozen=True, slots=True)
class GroundPlaneCamera:
    """``height`` (m) above the ground, ``pitch_degrees`` below the horizon,
    ``horizontal_field_of_view_degrees`` (square pixels, principal point at the image centre),
    ``maximum_range`` (m): ground farther than this along the optical axis is left unknown."""

    height: float
    pitch_degrees: float
    horizontal_field_of_view_degrees: float
    maximum_range: float = 60.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.height) and self.height > 0.0):
            raise ConfigurationError(f"camera height must be a positive number of metres, got {self.height}")
        if not (0.0 < self.pitch_degrees < 90.0):
            raise ConfigurationError(f"camera pitch must be between 0 and 90 degrees down, got {self.pitch_degrees}")
        if not (1.0 <= self.horizontal_field_of_view_degrees <= 170.0):
            raise ConfigurationError(
                f"horizontal field of view must be in [1, 170] degrees, got {self.horizontal_field_of_view_degrees}"
            )
        if not (self.maximum_range > 0.0):
            raise ConfigurationError(f"maximum range must be positive, got {self.maximum_range}")

    def intrinsics(self, width: int, height: int) -> CameraIntrinsics:
        focal = (width / 2.0) / math.tan(math.radians(self.horizontal_field_of_view_degrees) / 2.0)
        return CameraIntrinsics(focal, focal, (width - 1) / 2.0, (height - 1) / 2.0, width, height)

    def camera_to_world(self) -> Pose:
        pitch = math.radians(self.pitch_degrees)
        # Pitching down is a rotation about the world's y (left) axis by +pitch.
        about_y = np.array([[math.cos(pitch), 0.0, math.sin(pitch)], [0.0, 1.0, 0.0],
                            [-math.sin(pitch), 0.0, math.cos(pitch)]])
        return Pose(about_y @ WORLD_FROM_LEVEL_OPTICAL, np.array([0.0, 0.0, self.height]))


def _rays(intrinsics: CameraIntrinsics, pose: Pose, columns: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """World-frame directions of the rays through pixels, scaled so their optical z is 1."""
    optical = intrinsics.back_project(columns, rows, np.ones(np.broadcast(columns, rows).shape))
    return optical @ pose.rotation.T


def ground_depth(camera: GroundPlaneCamera, intrinsics: CameraIntrinsics, pose: Pose) -> np.ndarray:
    """The (H, W) float32 depth of the empty ground; NaN above the horizon or beyond range."""
    columns = np.arange(intrinsics.width, dtype=np.float64)[np.newaxis, :]
    rows = np.arange(intrinsics.height, dtype=np.float64)[:, np.newaxis]
    downward = -_rays(intrinsics, pose, columns, rows)[..., 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        depth = np.where(downward > 0.0, pose.translation[2] / downward, np.nan)
    depth[depth > camera.maximum_range] = np.nan
    return depth.astype(np.float32)


def foot_point(box: BoundingBox2D, intrinsics: CameraIntrinsics, pose: Pose) -> np.ndarray | None:
    """Where the bottom centre of ``box`` meets the ground (world frame), or None above the horizon."""
    _, _, _, bottom = box.corners
    ray = _rays(intrinsics, pose, np.array(box.center_x - 0.5), np.array(bottom - 0.5))
    if ray[2] >= 0.0:
        return None
    return pose.translation + ray * (pose.translation[2] / -ray[2])


def standing_depth(
    boxes: Sequence[BoundingBox2D], background: np.ndarray, camera: GroundPlaneCamera,
    intrinsics: CameraIntrinsics, pose: Pose,
) -> np.ndarray:
    """``background`` with each box painted as an upright board standing on its foot point.

    Boxes whose foot point is above the horizon or beyond range are left unpainted (their
    percepts are then dropped for lack of depth). Where boards overlap, the nearer wins.
    """
    depth = np.array(background, dtype=np.float32, copy=True)
    for box in boxes:
        foot = foot_point(box, intrinsics, pose)
        if foot is None:
            continue
        normal = np.array([foot[0] - pose.translation[0], foot[1] - pose.translation[1], 0.0])
        if np.linalg.norm(normal) < 1e-6:
            continue
        normal /= np.linalg.norm(normal)
        x_min, y_min, x_max, y_max = box.corners
        first_column, last_column = max(int(math.floor(x_min)), 0), min(int(math.ceil(x_max)), intrinsics.width)
        first_row, last_row = max(int(math.floor(y_min)), 0), min(int(math.ceil(y_max)), intrinsics.height)
        if first_column >= last_column or first_row >= last_row:
            continue
        columns = np.arange(first_column, last_column, dtype=np.float64)[np.newaxis, :]
        rows = np.arange(first_row, last_row, dtype=np.float64)[:, np.newaxis]
        facing = _rays(intrinsics, pose, columns, rows) @ normal
        with np.errstate(divide="ignore", invalid="ignore"):
            board = np.where(facing > 1e-9, float(normal @ (foot - pose.translation)) / facing, np.nan)
        board[board > camera.maximum_range] = np.nan
        window = depth[first_row:last_row, first_column:last_column]
        depth[first_row:last_row, first_column:last_column] = np.fmin(window, board.astype(np.float32))
    return depth
