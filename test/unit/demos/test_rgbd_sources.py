"""The real RGB-D source: Middlebury's Motorcycle with metric depth from its calibration."""

from __future__ import annotations

import numpy as np
import pytest

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor_demos.rgbd_sources import disparity_to_depth, load_source


def test_motorcycle_frame_has_registered_colour_and_metric_depth() -> None:
    (frame,) = load_source("motorcycle")
    assert frame.color.shape == (500, 741, 3) and frame.color.dtype == np.uint8
    assert frame.depth_metres.shape == (500, 741) and frame.depth_metres.dtype == np.float32
    valid = frame.depth_metres[np.isfinite(frame.depth_metres)]
    assert 0.8 < valid.size / frame.depth_metres.size < 1.0  # some pixels have no disparity
    # The motorcycle fills the middle of the image, about 2.6 m from the camera.
    centre = frame.depth_metres[200:300, 250:450]
    assert 2.2 < np.nanmedian(centre) < 3.0
    assert (frame.fx, frame.cx, frame.cy) == pytest.approx((994.978, 311.193, 254.877))


def test_unknown_disparities_become_nan_and_known_ones_follow_f_b_over_d() -> None:
    disparity = np.array([[np.inf, 0.0, -1.0, 68.914]], dtype=np.float32)
    depth = disparity_to_depth(disparity, focal_pixels=1000.0, baseline_metres=0.2, disparity_offset=31.086)
    assert np.isnan(depth[0, :3]).all()
    assert depth[0, 3] == pytest.approx(2.0, rel=1e-5)


def test_unknown_source_lists_the_known_ones() -> None:
    with pytest.raises(ConfigurationError, match="motorcycle"):
        load_source("kitchen")
