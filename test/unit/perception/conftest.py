"""Shared example scenes for the perception tests: real photos, real depth, real tracks.

Real data comes from installed packages only: scikit-image's Middlebury ``stereo_motorcycle``
(RGB + ground-truth disparity), Debian ``darknet``'s photos, motmetrics' TUD-Campus ground truth.
A test whose data package is missing is skipped with the command that installs it.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from merlin2_sailor.contract.camera import CameraIntrinsics

from .scenes import RgbdScene

# Middlebury 2014 "Motorcycle", down-sampled four times by scikit-image; its documented calibration.
MOTORCYCLE_FOCAL_LENGTH = 994.978  # pixels
MOTORCYCLE_PRINCIPAL_POINT = (311.193, 254.877)  # pixels
MOTORCYCLE_BASELINE = 0.193001  # metres
MOTORCYCLE_DISPARITY_OFFSET = 31.086  # pixels, the x difference of the two principal points


@pytest.fixture(scope="session")
def motorcycle_scene() -> RgbdScene:
    """The left image of the Middlebury motorcycle with depth from its ground-truth disparity.

    Checked against the data (not only the docstring): ``left[y, x]`` matches ``right[y, x - d]``
    (mean absolute difference 8 grey levels against ~38 for other hypotheses), so ``d`` is in
    pixels of this down-sampled image, and pixels without ground truth hold +inf, not NaN.
    Depth is ``f * B / (d + doffs)``: +inf disparity gives 0 m, which the core reads as unknown.
    """
    skimage_data = pytest.importorskip("skimage.data", reason="pip install scikit-image")
    left, _right, disparity = skimage_data.stereo_motorcycle()
    depth = MOTORCYCLE_FOCAL_LENGTH * MOTORCYCLE_BASELINE / (disparity.astype(np.float64) + MOTORCYCLE_DISPARITY_OFFSET)
    intrinsics = CameraIntrinsics(
        fx=MOTORCYCLE_FOCAL_LENGTH,
        fy=MOTORCYCLE_FOCAL_LENGTH,
        cx=MOTORCYCLE_PRINCIPAL_POINT[0],
        cy=MOTORCYCLE_PRINCIPAL_POINT[1],
        width=left.shape[1],
        height=left.shape[0],
    )
    return RgbdScene(image=left, depth=depth.astype(np.float32), intrinsics=intrinsics)


@pytest.fixture(scope="session")
def tud_campus_ground_truth() -> np.ndarray:
    """TUD-Campus ground truth rows (frame, id, x, y, width, height, ...) shipped with motmetrics."""
    if not hasattr(np, "asfarray"):  # motmetrics 1.4 still calls np.asfarray, gone in NumPy 2
        np.asfarray = lambda values, dtype=float: np.asarray(values, dtype=dtype)  # type: ignore[attr-defined]
    spec = importlib.util.find_spec("motmetrics")
    if spec is None or spec.origin is None:
        pytest.skip("pip install motmetrics==1.4.0")
    path = Path(spec.origin).parent / "data" / "TUD-Campus" / "gt.txt"
    return np.loadtxt(path, delimiter=",")
