"""Readers for the file formats of ViSP's RGB-D data sets (``ViSP-images/mbt-depth``).

- camera intrinsics: the ``<camera>`` element of a tracker configuration XML, with ``px``,
  ``py`` (focal lengths in pixels) and ``u0``, ``v0`` (principal point), for a distortion-free
  perspective projection;
- an extrinsic transform: a text file of a 4x4 homogeneous matrix, one row per line
  (``depth_M_color.txt`` maps points from the colour camera's frame into the depth camera's);
- a raw depth frame (``depth_image_NNNN.bin``): two little-endian uint32, height then width,
  then height x width little-endian uint16 depth values, row by row, 0 meaning no measurement.
"""

from __future__ import annotations

import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import InvalidInputError

DEPTH_HEADER = np.dtype([("height", "<u4"), ("width", "<u4")])


@dataclass(frozen=True, slots=True)
class PinholeParameters:
    """Focal lengths and principal point in pixels (no image size: ViSP's files carry none)."""

    fx: float
    fy: float
    cx: float
    cy: float


def read_camera_parameters(path: Path) -> PinholeParameters:
    """Read ``<conf><camera><px/><py/><u0/><v0/></camera></conf>``."""
    try:
        root = ElementTree.parse(path).getroot()
    except (OSError, ElementTree.ParseError) as error:
        raise InvalidInputError(f"cannot read the camera parameters in {path}: {error}") from error
    camera = root.find("camera")
    if camera is None:
        raise InvalidInputError(f"{path} has no <camera> element with the intrinsics")
    values = {}
    for tag in ("px", "py", "u0", "v0"):
        text = camera.findtext(tag)
        try:
            values[tag] = float(text) if text is not None else float("nan")
        except ValueError as error:
            raise InvalidInputError(f"{path}: <camera><{tag}> is not a number ({text!r})") from error
        if not np.isfinite(values[tag]):
            raise InvalidInputError(f"{path}: <camera> lacks <{tag}>")
    return PinholeParameters(values["px"], values["py"], values["u0"], values["v0"])


def read_homogeneous_matrix(path: Path) -> Pose:
    """Read a 4x4 homogeneous matrix written as four lines of four numbers."""
    try:
        matrix = np.loadtxt(path, dtype=np.float64)
    except (OSError, ValueError) as error:
        raise InvalidInputError(f"cannot read the 4x4 matrix in {path}: {error}") from error
    if matrix.shape != (4, 4):
        raise InvalidInputError(f"{path} holds a {matrix.shape} array, not a 4x4 homogeneous matrix")
    # The rotation is printed to ten digits; re-orthonormalise it so Pose's strict check holds.
    left, _, right = np.linalg.svd(matrix[:3, :3])
    matrix[:3, :3] = left @ right
    return Pose.from_matrix(matrix)


def read_raw_depth(path: Path) -> np.ndarray:
    """Read a ``depth_image_NNNN.bin`` frame as an (H, W) uint16 array of raw sensor units."""
    try:
        data = path.read_bytes()
    except OSError as error:
        raise InvalidInputError(f"cannot read the depth frame {path}: {error}") from error
    if len(data) < DEPTH_HEADER.itemsize:
        raise InvalidInputError(f"{path} is too short for a depth frame ({len(data)} bytes)")
    header = np.frombuffer(data, DEPTH_HEADER, count=1)[0]
    height, width = int(header["height"]), int(header["width"])
    expected = DEPTH_HEADER.itemsize + 2 * height * width
    if height == 0 or width == 0 or len(data) != expected:
        raise InvalidInputError(
            f"{path} says {width}x{height} depth pixels ({expected} bytes) but holds {len(data)} bytes"
        )
    return np.frombuffer(data, "<u2", offset=DEPTH_HEADER.itemsize).reshape(height, width).astype(np.uint16)
