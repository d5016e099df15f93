"""Camera frames annotated with what the anchoring layer made of them: boxes and symbols.

Anchors are projected into the frame through the camera pose at the frame's stamp: the 8 corners
of each anchor's 3D box give its image box, so the picture shows where the anchoring layer
believes each object is, not where the detector drew it. Detector boxes, when given, are drawn
thin and grey underneath, so a gap between the two is visible at a glance.

With the frame's depth image, an anchor hidden behind a wall is not drawn: a box drawn through
the wall of the next room reads as an object the camera sees. Hidden means that nearly all of the
box's pixels measure a surface clearly nearer than the anchor's nearest corner; a pixel without
depth (beyond the sensor's range) hides nothing.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.pose import Pose

_FONT = cv2.FONT_HERSHEY_SIMPLEX
_STATE_COLOURS = {"confirmed": (30, 90, 200), "missing": (220, 40, 40), "tentative": (160, 160, 160)}  # RGB


@dataclass(frozen=True)
class AnchorInView:
    """An anchor to draw: where it is believed to be, how big, and whether it was seen this frame."""

    symbol: str
    state: str
    position: tuple[float, float, float]
    size: tuple[float, float, float]
    seen_now: bool


Box = tuple[int, int, int, int]
OCCLUSION_MARGIN = 0.15  # m: depth noise plus a little; nearer than this in front of the anchor hides it
HIDDEN_FRACTION = 0.9  # of the box's pixels: a door frame across part of an object does not hide it


def anchor_box(anchor: AnchorInView, intrinsics: CameraIntrinsics, camera_to_world: Pose) -> Box | None:
    """The anchor's box in pixels (x0, y0, x1, y1), None when it is behind the camera or off-image."""
    projected = _project(anchor, intrinsics, camera_to_world)
    return projected[0] if projected is not None else None


def _project(anchor: AnchorInView, intrinsics: CameraIntrinsics, camera_to_world: Pose) -> tuple[Box, float] | None:
    """The anchor's box in pixels and the depth of its nearest corner."""
    half = np.asarray(anchor.size, dtype=float) / 2.0
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
    corners = np.asarray(anchor.position, dtype=float) + signs * half
    pixels, depth = intrinsics.project(camera_to_world.inverse().transform_points(corners))
    if not np.all(depth > 0.05) or not np.all(np.isfinite(pixels)):
        return None
    x0, y0 = np.floor(pixels.min(axis=0)).astype(int)
    x1, y1 = np.ceil(pixels.max(axis=0)).astype(int)
    x0, x1 = max(x0, 0), min(x1, intrinsics.width - 1)
    y0, y1 = max(y0, 0), min(y1, intrinsics.height - 1)
    if x1 <= x0 or y1 <= y0:
        return None
    return (int(x0), int(y0), int(x1), int(y1)), float(depth.min())


def hidden_by_nearer_surface(box: Box, nearest_depth: float, depth: np.ndarray) -> bool:
    """Whether nearly all of the box shows a surface clearly in front of the anchor."""
    x0, y0, x1, y1 = box
    region = np.asarray(depth, dtype=np.float64)[y0 : y1 + 1, x0 : x1 + 1]
    in_front = np.isfinite(region) & (region > 0.0) & (region < nearest_depth - OCCLUSION_MARGIN)
    return bool(in_front.mean() >= HIDDEN_FRACTION)


def annotate_frame(
    rgb: np.ndarray,
    intrinsics: CameraIntrinsics,
    camera_to_world: Pose,
    anchors: Sequence[AnchorInView],
    detector_boxes: Sequence[tuple[float, float, float, float]] = (),
    caption: str = "",
    depth: np.ndarray | None = None,
) -> np.ndarray:
    """A copy of the RGB frame with detector boxes, anchor boxes and symbols, and a caption.

    ``depth`` (metres, NaN or 0 where unknown, registered to ``rgb``) hides anchors behind walls.
    """
    image = np.ascontiguousarray(rgb.copy())
    for x0, y0, x1, y1 in detector_boxes:
        cv2.rectangle(image, (int(x0), int(y0)), (int(x1), int(y1)), (170, 170, 170), 1)
    for anchor in anchors:
        projected = _project(anchor, intrinsics, camera_to_world)
        if projected is None:
            continue
        box, nearest_depth = projected
        if depth is not None and hidden_by_nearer_surface(box, nearest_depth, depth):
            continue
        colour = _STATE_COLOURS.get(anchor.state, (0, 0, 0))
        x0, y0, x1, y1 = box
        cv2.rectangle(image, (x0, y0), (x1, y1), colour, 2 if anchor.seen_now else 1)
        label = anchor.symbol if anchor.state != "missing" else f"{anchor.symbol} (missing)"
        (width, height), _ = cv2.getTextSize(label, _FONT, 0.45, 1)
        top = max(y0 - height - 4, 0)
        cv2.rectangle(image, (x0, top), (x0 + width + 4, top + height + 4), colour, -1)
        cv2.putText(image, label, (x0 + 2, top + height + 1), _FONT, 0.45, (255, 255, 255), 1, cv2.LINE_AA)
    if caption:
        cv2.rectangle(image, (0, image.shape[0] - 22), (image.shape[1], image.shape[0]), (0, 0, 0), -1)
        cv2.putText(image, caption, (6, image.shape[0] - 7), _FONT, 0.45, (255, 255, 255), 1, cv2.LINE_AA)
    return image
