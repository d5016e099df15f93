"""Synthetic scenes with geometry known in closed form, shared by the perception tests."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.contract.pose import Pose

# scripts/fetch_test_data.sh unpacks Debian's darknet package and `make test` exports where.
DARKNET_DATA = Path(os.environ.get("SAILOR_DARKNET_DATA") or "/usr/share/darknet/data")


@dataclass(frozen=True)
class RgbdScene:
    image: np.ndarray  # (H, W, 3) uint8 RGB
    depth: np.ndarray  # (H, W) float32 metres, NaN where unknown
    intrinsics: CameraIntrinsics


#: A box drawn by hand around the whole motorcycle (rear light to front tyre, mirrors to tyres).
MOTORCYCLE_BOX = BoundingBox2D.from_corners(90.0, 75.0, 690.0, 455.0)


def load_darknet_image(name: str) -> np.ndarray:
    """An RGB photo from Debian's darknet package, e.g. ``dog`` or ``person``."""
    cv2 = pytest.importorskip("cv2", reason="pip install opencv-python-headless")
    path = DARKNET_DATA / f"{name}.jpg"
    if not path.is_file():
        pytest.skip(f"{path} is missing: apt-get install darknet")
    return cv2.cvtColor(cv2.imread(str(path)), cv2.COLOR_BGR2RGB)


def optical_camera_pose(position: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> Pose:
    """A camera at ``position`` in a REP 103 world (x forward, y left, z up), looking along +x.

    The optical frame's z (forward) is the world's x, its x (right) the world's -y and its
    y (down) the world's -z: the rotation every ROS camera_link -> optical frame transform holds.
    """
    rotation = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    return Pose(rotation, np.asarray(position, dtype=np.float64))


def wall_with_box_scene(
    wall_depth: float = 4.0,
    object_depth: float = 2.0,
    object_corners: tuple[int, int, int, int] = (200, 150, 300, 330),
    width: int = 640,
    height: int = 480,
) -> tuple[np.ndarray, CameraIntrinsics]:
    """Depth of a flat wall facing the camera with a flat rectangular object in front of it.

    The object occupies pixel columns x0..x1-1 and rows y0..y1-1, so its true extent is known in
    closed form from the intrinsics: that is what the box tests compare against.
    """
    intrinsics = CameraIntrinsics(fx=525.0, fy=525.0, cx=319.5, cy=239.5, width=width, height=height)
    depth = np.full((height, width), wall_depth, dtype=np.float32)
    x0, y0, x1, y1 = object_corners
    depth[y0:y1, x0:x1] = object_depth
    return depth, intrinsics
