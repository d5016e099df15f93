"""Real RGB-D frames that ship inside installable packages, for demos and replays offline.

A source yields RgbdFrame objects: colour, depth in metres (NaN where unknown) and pinhole
intrinsics. The first source is scikit-image's ``stereo_motorcycle``: a real Middlebury stereo
pair whose disparity map, with the published calibration, gives true metric depth.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.errors import ConfigurationError, DependencyError


@dataclass(frozen=True, eq=False)
class RgbdFrame:
    """One registered colour + depth frame with the intrinsics of the (shared) pinhole camera."""

    color: np.ndarray  # (H, W, 3) uint8, RGB
    depth_metres: np.ndarray  # (H, W) float32, NaN where unknown
    fx: float
    fy: float
    cx: float
    cy: float

    @property
    def width(self) -> int:
        return int(self.color.shape[1])

    @property
    def height(self) -> int:
        return int(self.color.shape[0])


# Calibration of the Middlebury 2014 "Motorcycle" pair at the resolution scikit-image ships
# (a quarter of the original): focal length and principal point in pixels, baseline in metres,
# and the disparity offset between the two principal points.
MOTORCYCLE_FOCAL_PIXELS = 994.978
MOTORCYCLE_CX = 311.193
MOTORCYCLE_CY = 254.877
MOTORCYCLE_BASELINE_METRES = 0.193001
MOTORCYCLE_DISPARITY_OFFSET = 31.086


def disparity_to_depth(disparity: np.ndarray, focal_pixels: float, baseline_metres: float,
                       disparity_offset: float) -> np.ndarray:
    """Depth = f * B / (d + doffs); unknown disparities (inf, NaN, <= 0) become NaN."""
    disparity = disparity.astype(np.float32)
    valid = np.isfinite(disparity) & (disparity > 0.0)
    depth = np.full(disparity.shape, np.nan, dtype=np.float32)
    depth[valid] = focal_pixels * baseline_metres / (disparity[valid] + disparity_offset)
    return depth


def motorcycle_frames() -> list[RgbdFrame]:
    """The left image of Middlebury's Motorcycle with depth from its ground-truth disparity."""
    try:
        from skimage import data
    except ImportError as error:
        raise DependencyError("the 'motorcycle' source needs scikit-image (pip install scikit-image)") from error
    left, _right, disparity = data.stereo_motorcycle()
    depth = disparity_to_depth(
        disparity, MOTORCYCLE_FOCAL_PIXELS, MOTORCYCLE_BASELINE_METRES, MOTORCYCLE_DISPARITY_OFFSET
    )
    return [RgbdFrame(np.ascontiguousarray(left), depth, MOTORCYCLE_FOCAL_PIXELS,
                      MOTORCYCLE_FOCAL_PIXELS, MOTORCYCLE_CX, MOTORCYCLE_CY)]


SOURCES: dict[str, Callable[[], list[RgbdFrame]]] = {
    "motorcycle": motorcycle_frames,
}


def load_source(name: str) -> list[RgbdFrame]:
    """Return the frames of a named source, or fail with the list of known sources."""
    if name not in SOURCES:
        raise ConfigurationError(f"unknown RGB-D source '{name}'; known sources: {', '.join(sorted(SOURCES))}")
    return SOURCES[name]()
