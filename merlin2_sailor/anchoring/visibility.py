"""Should an anchor have been seen in this frame? In the frustum, and not hidden by nearer depth.

Marking an anchor missing because it was not detected is only fair if the camera could have
detected it: it must project inside the image within the sensor's range, and nothing nearer may
stand in front of it. The depth image answers the second question: at the anchor's pixel, a
measured depth clearly smaller than the anchor's own depth means something is in front.
"Clearly" is ``occlusion_margin`` plus half the anchor's largest extent, since the camera sees
the object's front surface, not its centre. A pixel without depth (NaN or 0) proves nothing, so
the anchor is then *not* expected to be visible: a wrong "missing" costs more than a late one.

The anchor's centre in the image is not enough for a large object close by: a detector finds an
object from what of it is in the picture, and a bicycle 0.5 m from the camera, its centre in the
image, is mostly outside it. So the anchor's whole 3D box is projected too, and at least
``in_image_share`` of the projected box must lie inside the image (a box reaching behind the
camera is not in view). Without that, the bicycle beside the living room's waypoint was marked
missing each time the robot stood there to look for it, and a search that had seen it from the
kitchen gave up (scenario suite, `large_object_wheeled_away`, network, 6 December 2026).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from merlin2_sailor.contract.camera import CameraIntrinsics, FrustumLimits, points_in_frustum
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import ConfigurationError, InvalidInputError


@dataclass(frozen=True, slots=True, eq=False)
class CameraView:
    """What the camera could see in one frame: its intrinsics, its pose in the world frame at the
    image stamp (camera-to-world, optical frame) and, optionally, the registered depth image in
    metres (NaN or 0 where unknown), which enables the occlusion test."""

    intrinsics: CameraIntrinsics
    camera_to_world: Pose
    depth: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.depth is not None:
            depth = np.asarray(self.depth)
            if depth.shape != (self.intrinsics.height, self.intrinsics.width):
                raise InvalidInputError(
                    f"The depth image is {depth.shape} but the intrinsics describe "
                    f"{self.intrinsics.height}x{self.intrinsics.width} pixels; register depth to the colour image."
                )

    @property
    def position(self) -> np.ndarray:
        """The camera's optical centre in the world frame."""
        return np.asarray(self.camera_to_world.translation)


@dataclass(frozen=True, slots=True)
class VisibilityConfig:
    """``frustum``: the range and image margin in which objects count as visible;
    ``occlusion_margin`` (m): how much nearer than the object's front a depth reading must be to
    count as an occluder (depth noise of RGB-D sensors is a few centimetres at a few metres);
    ``in_image_share``: how much of an object's projected box must be inside the image for it to
    count as visible (see the module; 0 turns that off)."""

    frustum: FrustumLimits = field(default_factory=lambda: FrustumLimits(near=0.2, far=6.0, margin=10.0))
    occlusion_margin: float = 0.1
    in_image_share: float = 0.5

    def __post_init__(self) -> None:
        if not (math.isfinite(self.occlusion_margin) and self.occlusion_margin >= 0.0):
            raise ConfigurationError(f"visibility occlusion_margin must be >= 0 metres, got {self.occlusion_margin}.")
        if not (0.0 <= self.in_image_share <= 1.0):
            raise ConfigurationError(f"visibility in_image_share must be in [0, 1] (0 turns it off), "
                                     f"got {self.in_image_share}.")


def should_be_visible(
    positions: np.ndarray, sizes: np.ndarray, view: CameraView, config: VisibilityConfig
) -> np.ndarray:
    """Return an (N,) bool array: which objects the camera should have seen in this frame."""
    positions = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    sizes = np.asarray(sizes, dtype=np.float64).reshape(-1, 3)
    if len(positions) == 0:
        return np.zeros(0, dtype=bool)
    visible = points_in_frustum(view.intrinsics, view.camera_to_world, positions, config.frustum)
    if config.in_image_share > 0.0 and visible.any():
        candidates = np.flatnonzero(visible)
        visible[candidates] = in_image_shares(positions[candidates], sizes[candidates], view) >= config.in_image_share
    if view.depth is None or not visible.any():
        return visible
    candidates = np.flatnonzero(visible)
    points_camera = view.camera_to_world.inverse().transform_points(positions[candidates])
    pixels, object_depth = view.intrinsics.project(points_camera)
    columns = np.clip(np.rint(pixels[:, 0]).astype(np.intp), 0, view.intrinsics.width - 1)
    rows = np.clip(np.rint(pixels[:, 1]).astype(np.intp), 0, view.intrinsics.height - 1)
    measured = np.asarray(view.depth, dtype=np.float64)[rows, columns]
    known = np.isfinite(measured) & (measured > 0.0)
    front_surface = object_depth - 0.5 * sizes[candidates].max(axis=1)
    occluded = measured < front_surface - config.occlusion_margin
    visible[candidates] = known & ~occluded
    return visible


#: The eight corners of a unit box centred on the origin, as multiples of its size.
_CORNERS = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])


def in_image_shares(positions: np.ndarray, sizes: np.ndarray, view: CameraView) -> np.ndarray:
    """(N,) the share of each 3D box's projection (the image rectangle around its corners) that lies
    inside the image; 0 for a box with a corner at or behind the camera's plane."""
    corners = (positions[:, np.newaxis, :] + sizes[:, np.newaxis, :] * _CORNERS).reshape(-1, 3)
    pixels, depth = view.intrinsics.project(view.camera_to_world.inverse().transform_points(corners))
    pixels = pixels.reshape(len(positions), len(_CORNERS), 2)
    in_front = (depth.reshape(len(positions), len(_CORNERS)) > 0.0).all(axis=1)
    shares = np.zeros(len(positions))
    if not in_front.any():
        return shares
    low, high = pixels[in_front].min(axis=1), pixels[in_front].max(axis=1)
    limits = np.array([view.intrinsics.width, view.intrinsics.height], dtype=np.float64)
    inside = np.prod(np.clip(np.minimum(high, limits) - np.maximum(low, 0.0), 0.0, None), axis=1)
    area = np.prod(np.maximum(high - low, 1e-9), axis=1)
    shares[in_front] = inside / area
    return shares
