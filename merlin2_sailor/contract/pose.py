"""A rigid transform between two frames, as tf2 would hand it over.

Anchors live in a fixed world frame, so every 3D measurement made in the camera frame has to be
moved with the camera pose taken at the image's timestamp. A small value type of our own keeps
that arithmetic testable without tf2: the ROS layer converts a ``TransformStamped`` into a
:class:`Pose` once, and everything downstream composes, inverts and applies it with NumPy.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.errors import InvalidInputError

#: Largest deviation from orthonormality accepted for a rotation matrix; matrices that come from
#: quaternions or tf2 are orthonormal to ~1e-15, so anything beyond this is a caller's bug.
ROTATION_TOLERANCE = 1e-6


@dataclass(frozen=True, slots=True, eq=False)
class Pose:
    """A rigid transform ``target <- source``: ``p_target = rotation @ p_source + translation``.

    Read ``Pose`` for the camera in the world as "camera-to-world": it maps points expressed in
    the camera frame into the world frame, exactly like a tf2 lookup of ``world <- camera``.
    The arrays are copied and made read-only on construction, so a pose can be shared between
    threads and cached on a percept without anyone changing it behind its back.
    """

    rotation: np.ndarray  # (3, 3) orthonormal, determinant +1
    translation: np.ndarray  # (3,) metres

    def __post_init__(self) -> None:
        rotation = np.array(self.rotation, dtype=np.float64)
        translation = np.array(self.translation, dtype=np.float64).reshape(-1)
        if rotation.shape != (3, 3):
            raise InvalidInputError(f"A pose rotation must be a 3x3 matrix, got shape {rotation.shape}.")
        if translation.shape != (3,):
            raise InvalidInputError(f"A pose translation must have 3 values, got {translation.size}.")
        if not (np.all(np.isfinite(rotation)) and np.all(np.isfinite(translation))):
            raise InvalidInputError("A pose must not contain NaN or infinite values.")
        if not np.allclose(rotation @ rotation.T, np.eye(3), atol=ROTATION_TOLERANCE) or (
            np.linalg.det(rotation) < 0.0
        ):
            raise InvalidInputError(
                "A pose rotation must be orthonormal with determinant +1 (a proper rotation); "
                "build it from a unit quaternion with Pose.from_quaternion if unsure."
            )
        rotation.setflags(write=False)
        translation.setflags(write=False)
        object.__setattr__(self, "rotation", rotation)
        object.__setattr__(self, "translation", translation)

    @classmethod
    def identity(cls) -> Pose:
        return cls(np.eye(3), np.zeros(3))

    @classmethod
    def from_quaternion(cls, quaternion_xyzw: Sequence[float], translation: Sequence[float] = (0.0, 0.0, 0.0)) -> Pose:
        """Build a pose from a quaternion in ROS order (x, y, z, w) and a translation.

        The quaternion is normalised first because values read from messages or YAML files are
        rarely exactly unit length; a zero quaternion has no meaning and is rejected.
        """
        quaternion = np.asarray(quaternion_xyzw, dtype=np.float64).reshape(-1)
        if quaternion.shape != (4,):
            raise InvalidInputError(f"A quaternion needs 4 values (x, y, z, w), got {quaternion.size}.")
        norm = float(np.linalg.norm(quaternion))
        if not np.isfinite(norm) or norm < 1e-9:
            raise InvalidInputError(f"The quaternion {quaternion.tolist()} has no direction (norm {norm}).")
        x, y, z, w = quaternion / norm
        rotation = np.array(
            [
                [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w)],
                [2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w)],
                [2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)],
            ]
        )
        return cls(rotation, np.asarray(translation, dtype=np.float64))

    @classmethod
    def from_matrix(cls, matrix: np.ndarray) -> Pose:
        """Build a pose from a 4x4 homogeneous matrix."""
        matrix = np.asarray(matrix, dtype=np.float64)
        if matrix.shape != (4, 4):
            raise InvalidInputError(f"A homogeneous transform must be 4x4, got shape {matrix.shape}.")
        if not np.allclose(matrix[3], (0.0, 0.0, 0.0, 1.0)):
            raise InvalidInputError("The last row of a homogeneous transform must be (0, 0, 0, 1).")
        return cls(matrix[:3, :3], matrix[:3, 3])

    @property
    def matrix(self) -> np.ndarray:
        """The 4x4 homogeneous matrix of this transform."""
        matrix = np.eye(4)
        matrix[:3, :3] = self.rotation
        matrix[:3, 3] = self.translation
        return matrix

    @property
    def quaternion_xyzw(self) -> np.ndarray:
        """The rotation as a unit quaternion (x, y, z, w) with w >= 0."""
        r = self.rotation
        trace = float(np.trace(r))
        # Shepperd's method: divide by the largest of the four candidate denominators, which keeps
        # the conversion accurate for rotations near 180 degrees where w approaches zero.
        candidates = (trace, r[0, 0], r[1, 1], r[2, 2])
        largest = int(np.argmax(candidates))
        if largest == 0:
            s = 2.0 * np.sqrt(1.0 + trace)
            quaternion = ((r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s, s / 4)
        elif largest == 1:
            s = 2.0 * np.sqrt(1.0 + r[0, 0] - r[1, 1] - r[2, 2])
            quaternion = (s / 4, (r[0, 1] + r[1, 0]) / s, (r[0, 2] + r[2, 0]) / s, (r[2, 1] - r[1, 2]) / s)
        elif largest == 2:
            s = 2.0 * np.sqrt(1.0 + r[1, 1] - r[0, 0] - r[2, 2])
            quaternion = ((r[0, 1] + r[1, 0]) / s, s / 4, (r[1, 2] + r[2, 1]) / s, (r[0, 2] - r[2, 0]) / s)
        else:
            s = 2.0 * np.sqrt(1.0 + r[2, 2] - r[0, 0] - r[1, 1])
            quaternion = ((r[0, 2] + r[2, 0]) / s, (r[1, 2] + r[2, 1]) / s, s / 4, (r[1, 0] - r[0, 1]) / s)
        result = np.asarray(quaternion, dtype=np.float64)
        return -result if result[3] < 0.0 else result

    def compose(self, other: Pose) -> Pose:
        """Return ``self * other``: apply ``other`` first, then ``self``.

        With ``world_from_base.compose(base_from_camera)`` you get ``world_from_camera``, the same
        chaining tf2 does along a frame tree.
        """
        return Pose(self.rotation @ other.rotation, self.rotation @ other.translation + self.translation)

    def __matmul__(self, other: Pose) -> Pose:
        return self.compose(other)

    def inverse(self) -> Pose:
        """Return the transform in the opposite direction (``source <- target``)."""
        rotation_transposed = self.rotation.T
        return Pose(rotation_transposed, -rotation_transposed @ self.translation)

    def transform_points(self, points: np.ndarray) -> np.ndarray:
        """Map an (..., 3) array of points from the source frame to the target frame."""
        points = np.asarray(points, dtype=np.float64)
        if points.shape[-1] != 3:
            raise InvalidInputError(f"Points must have 3 coordinates in the last axis, got shape {points.shape}.")
        return points @ self.rotation.T + self.translation
