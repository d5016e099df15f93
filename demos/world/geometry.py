"""Plane geometry of the simulated world: 2D poses, segments and axis-aligned boxes.

The world is flat: the robot moves on the floor plane (x, y, yaw) and every wall, piece of
furniture and object is an axis-aligned box or a vertical wall segment. Everything here is plain
NumPy so that the navigation graph, the scenario's visibility test and the gripper share it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


def wrap_angle(angle: float) -> float:
    """The same angle in [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


@dataclass(frozen=True, slots=True)
class Pose2D:
    """A pose on the floor plane: position (metres) and heading (radians, counter-clockwise from +x)."""

    x: float
    y: float
    yaw: float

    @property
    def position(self) -> np.ndarray:
        return np.array([self.x, self.y])

    def distance_to(self, x: float, y: float) -> float:
        return math.hypot(x - self.x, y - self.y)

    def compose(self, forward: float, left: float, turn: float) -> Pose2D:
        """This pose moved by a displacement expressed in its own frame (forward, left, turn)."""
        cos_yaw, sin_yaw = math.cos(self.yaw), math.sin(self.yaw)
        return Pose2D(
            self.x + cos_yaw * forward - sin_yaw * left,
            self.y + sin_yaw * forward + cos_yaw * left,
            wrap_angle(self.yaw + turn),
        )

    def relative_to(self, other: Pose2D) -> tuple[float, float, float]:
        """The displacement (forward, left, turn) that takes ``other`` to this pose, in ``other``'s frame."""
        dx, dy = self.x - other.x, self.y - other.y
        cos_yaw, sin_yaw = math.cos(other.yaw), math.sin(other.yaw)
        return cos_yaw * dx + sin_yaw * dy, -sin_yaw * dx + cos_yaw * dy, wrap_angle(self.yaw - other.yaw)

    def as_dict(self) -> dict[str, float]:
        return {"x": float(self.x), "y": float(self.y), "yaw": float(self.yaw)}


@dataclass(frozen=True, slots=True)
class Box:
    """An axis-aligned box: ``center`` (x, y, z) and ``size`` (x, y, z extents), metres."""

    center: tuple[float, float, float]
    size: tuple[float, float, float]

    @property
    def minimum(self) -> np.ndarray:
        return np.asarray(self.center) - np.asarray(self.size) / 2.0

    @property
    def maximum(self) -> np.ndarray:
        return np.asarray(self.center) + np.asarray(self.size) / 2.0

    @property
    def top(self) -> float:
        return self.center[2] + self.size[2] / 2.0

    def contains_xy(self, x: float, y: float, margin: float = 0.0) -> bool:
        low, high = self.minimum, self.maximum
        return bool(low[0] - margin <= x <= high[0] + margin and low[1] - margin <= y <= high[1] + margin)

    def corners(self) -> np.ndarray:
        """The (8, 3) corners."""
        low, high = self.minimum, self.maximum
        return np.array([[x, y, z] for x in (low[0], high[0]) for y in (low[1], high[1]) for z in (low[2], high[2])])


def point_segment_distance(points: np.ndarray, start: np.ndarray, end: np.ndarray) -> np.ndarray:
    """Distance from each of (N, 2) points to the segment start-end."""
    points = np.atleast_2d(np.asarray(points, dtype=np.float64))
    direction = np.asarray(end, dtype=np.float64) - start
    length_squared = float(direction @ direction)
    if length_squared == 0.0:
        return np.linalg.norm(points - start, axis=1)
    fraction = np.clip((points - start) @ direction / length_squared, 0.0, 1.0)
    return np.linalg.norm(points - (start + fraction[:, None] * direction), axis=1)


def segments_intersect(start_a: np.ndarray, end_a: np.ndarray, start_b: np.ndarray, end_b: np.ndarray) -> bool:
    """Whether two closed segments cross or touch (collinear overlaps count)."""
    def orientation(p: np.ndarray, q: np.ndarray, r: np.ndarray) -> float:
        return float((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]))

    def on_segment(p: np.ndarray, q: np.ndarray, r: np.ndarray) -> bool:
        return bool(min(p[0], r[0]) - 1e-12 <= q[0] <= max(p[0], r[0]) + 1e-12
                    and min(p[1], r[1]) - 1e-12 <= q[1] <= max(p[1], r[1]) + 1e-12)

    o1, o2 = orientation(start_a, end_a, start_b), orientation(start_a, end_a, end_b)
    o3, o4 = orientation(start_b, end_b, start_a), orientation(start_b, end_b, end_a)
    if ((o1 > 0) != (o2 > 0)) and ((o3 > 0) != (o4 > 0)) and o1 != 0 and o2 != 0 and o3 != 0 and o4 != 0:
        return True
    return ((o1 == 0 and on_segment(start_a, start_b, end_a)) or (o2 == 0 and on_segment(start_a, end_b, end_a))
            or (o3 == 0 and on_segment(start_b, start_a, end_b)) or (o4 == 0 and on_segment(start_b, end_a, end_b)))


def segment_segment_distance(start_a: np.ndarray, end_a: np.ndarray, start_b: np.ndarray, end_b: np.ndarray) -> float:
    """Shortest distance between two segments (0 when they cross)."""
    start_a, end_a = np.asarray(start_a, dtype=np.float64), np.asarray(end_a, dtype=np.float64)
    start_b, end_b = np.asarray(start_b, dtype=np.float64), np.asarray(end_b, dtype=np.float64)
    if segments_intersect(start_a, end_a, start_b, end_b):
        return 0.0
    return float(min(
        point_segment_distance(np.stack([start_a, end_a]), start_b, end_b).min(),
        point_segment_distance(np.stack([start_b, end_b]), start_a, end_a).min(),
    ))


def segment_rectangle_distance(start: np.ndarray, end: np.ndarray, low: np.ndarray, high: np.ndarray) -> float:
    """Shortest distance between a segment and an axis-aligned rectangle (0 when they overlap)."""
    start, end = np.asarray(start, dtype=np.float64), np.asarray(end, dtype=np.float64)
    if all(low[i] <= start[i] <= high[i] for i in (0, 1)) or all(low[i] <= end[i] <= high[i] for i in (0, 1)):
        return 0.0
    corners = [np.array(c) for c in ((low[0], low[1]), (high[0], low[1]), (high[0], high[1]), (low[0], high[1]))]
    return min(segment_segment_distance(start, end, corners[i], corners[(i + 1) % 4]) for i in range(4))
