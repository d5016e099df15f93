"""Which objects the camera sees, and how much of each: the truth behind the simulated detector.

Two ways, one answer shape (:class:`Visibility`):

- ``visible_in_frame``: from a rendered frame's instance image, pixel-exact: occlusion by walls,
  furniture and other objects, truncation at the image border. The visible fraction is the number
  of the object's pixels over the area of its unoccluded silhouette (the convex hull of its
  projected corners), and the box is the bounding box of the pixels that are visible.
- ``visible_geometric``: without a frame (the world runs with rendering off): the silhouette
  clipped to the image, times the share of its image columns where it is nearer than the walls.
  Furniture does not occlude in this mode.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor_demos.world.geometry import Box
from merlin2_sailor_demos.world.rasteriser import NEAR_PLANE


@dataclass(frozen=True, slots=True)
class Visibility:
    """``index`` into the object list given; ``box`` of the visible part in pixels; ``depth`` of the centre (m)."""

    index: int
    fraction: float
    box: BoundingBox2D
    depth: float


@dataclass(frozen=True, slots=True)
class _Silhouette:
    hull: np.ndarray  # (K, 2) float32 pixel polygon, unclipped
    area: float
    depth: float  # of the box centre
    nearest: float  # smallest corner depth


def _silhouette(box: Box, world_to_camera: Pose, intrinsics: CameraIntrinsics) -> _Silhouette | None:
    corners = world_to_camera.transform_points(box.corners())
    if np.any(corners[:, 2] < NEAR_PLANE):
        return None  # reaching behind the camera: too close to be seen whole, not detectable
    pixels, _ = intrinsics.project(corners)
    hull = cv2.convexHull(pixels.astype(np.float32)).reshape(-1, 2)
    centre = world_to_camera.transform_points(np.asarray(box.center, dtype=np.float64)[None, :])[0]
    return _Silhouette(hull, float(cv2.contourArea(hull)), float(centre[2]), float(corners[:, 2].min()))


def _image_polygon(intrinsics: CameraIntrinsics) -> np.ndarray:
    right, bottom = intrinsics.width - 0.5, intrinsics.height - 0.5
    return np.array([[-0.5, -0.5], [right, -0.5], [right, bottom], [-0.5, bottom]], dtype=np.float32)


def visible_geometric(boxes: Sequence[Box], camera_pose: Pose, intrinsics: CameraIntrinsics,
                      wall_depth: np.ndarray | None = None) -> list[Visibility]:
    """Visibility of each box from geometry alone; ``wall_depth`` is the walls' depth per image column."""
    world_to_camera = camera_pose.inverse()
    image = _image_polygon(intrinsics)
    result = []
    for index, box in enumerate(boxes):
        silhouette = _silhouette(box, world_to_camera, intrinsics)
        if silhouette is None or silhouette.area <= 0.0:
            continue
        area, clipped = cv2.intersectConvexConvex(silhouette.hull, image)
        if area <= 0.0 or clipped is None:
            continue
        clipped = clipped.reshape(-1, 2)
        fraction = area / silhouette.area
        x_min, y_min = clipped.min(axis=0)
        x_max, y_max = clipped.max(axis=0)
        if wall_depth is not None:
            columns = wall_depth[max(int(np.floor(x_min + 0.5)), 0):int(np.ceil(x_max + 0.5)) + 1]
            fraction *= float(np.mean(columns > silhouette.nearest)) if columns.size else 0.0
        if fraction > 0.0:
            result.append(Visibility(index, min(float(fraction), 1.0),
                                     BoundingBox2D.from_corners(float(x_min) + 0.5, float(y_min) + 0.5,
                                                                float(x_max) + 0.5, float(y_max) + 0.5),
                                     silhouette.depth))
    return result


def visible_in_frame(boxes: Sequence[Box], instance: np.ndarray, camera_pose: Pose,
                     intrinsics: CameraIntrinsics) -> list[Visibility]:
    """Visibility of each box (box i drew instance id i) from a rendered frame's instance image."""
    counts = np.bincount(instance.ravel().astype(np.int64) + 1, minlength=len(boxes) + 1)[1:len(boxes) + 1]
    world_to_camera = camera_pose.inverse()
    height, width = instance.shape
    result = []
    for index in np.flatnonzero(counts):
        silhouette = _silhouette(boxes[index], world_to_camera, intrinsics)
        if silhouette is None or silhouette.area <= 0.0:
            continue
        x_min, y_min = np.floor(silhouette.hull.min(axis=0)).astype(int)
        x_max, y_max = np.ceil(silhouette.hull.max(axis=0)).astype(int)
        x_min, y_min, x_max, y_max = max(x_min, 0), max(y_min, 0), min(x_max, width - 1), min(y_max, height - 1)
        rows, columns = np.nonzero(instance[y_min:y_max + 1, x_min:x_max + 1] == index)
        if rows.size == 0:
            continue
        box = BoundingBox2D.from_corners(float(x_min + columns.min()), float(y_min + rows.min()),
                                         float(x_min + columns.max() + 1), float(y_min + rows.max() + 1))
        fraction = min(float(counts[index]) / max(silhouette.area, 1.0), 1.0)
        result.append(Visibility(int(index), fraction, box, silhouette.depth))
    return result
