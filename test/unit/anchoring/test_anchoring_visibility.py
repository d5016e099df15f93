"""should_be_visible(): frustum and occlusion."""

from __future__ import annotations

import numpy as np
import pytest

from merlin2_sailor.anchoring import CameraView, VisibilityConfig
from merlin2_sailor.anchoring.visibility import in_image_shares, should_be_visible
from merlin2_sailor.errors import ConfigurationError, InvalidInputError

from .anchoring_scenes import TEST_INTRINSICS, camera_view, flat_depth, looking_along_x, with_occluder

SIZES = np.full((1, 3), 0.1)


def visible(point, view, config=None):
    return bool(should_be_visible(np.array([point]), SIZES, view, config or VisibilityConfig())[0])


def test_frustum_limits():
    view = camera_view()
    assert visible((3.0, 0.0, 1.0), view)
    assert not visible((-3.0, 0.0, 1.0), view)  # behind
    assert not visible((3.0, 5.0, 1.0), view)  # far to the left, outside the image
    assert not visible((0.1, 0.0, 1.0), view)  # nearer than the sensor's minimum range
    assert not visible((7.0, 0.0, 1.0), view)  # beyond the configured 6 m
    assert visible((3.0, 1.6, 1.0), view)  # near the image border, inside


def test_occlusion_needs_clearly_nearer_depth():
    view = camera_view()
    point = (3.0, 0.0, 1.0)
    assert visible(point, camera_view(depth=flat_depth(3.5)))  # a wall behind it
    assert not visible(point, camera_view(depth=with_occluder(flat_depth(3.5), view, point, 1.5)))
    assert visible(point, camera_view(depth=with_occluder(flat_depth(3.5), view, point, 2.96)))  # its own front
    assert not visible(point, camera_view(depth=flat_depth(np.nan)))
    assert not visible(point, camera_view(depth=flat_depth(0.0)))


def test_a_large_object_is_not_hidden_by_its_own_front_surface():
    view = camera_view()
    sofa = np.array([[3.0, 0.0, 1.0]])
    depth = with_occluder(flat_depth(5.0), view, sofa[0], 2.6)  # its front, 0.4 m before its centre
    assert not should_be_visible(sofa, SIZES, camera_view(depth=depth), VisibilityConfig())[0]
    assert should_be_visible(sofa, np.array([[0.9, 0.9, 0.9]]), camera_view(depth=depth), VisibilityConfig())[0]


def test_depth_must_match_the_intrinsics():
    with pytest.raises(InvalidInputError, match="register"):
        CameraView(TEST_INTRINSICS, looking_along_x((0, 0, 1)), np.zeros((10, 10)))


def test_visibility_configuration_is_validated():
    with pytest.raises(ConfigurationError, match="occlusion_margin"):
        VisibilityConfig(occlusion_margin=-0.1)


def test_empty_input():
    assert should_be_visible(np.zeros((0, 3)), np.zeros((0, 3)), camera_view(), VisibilityConfig()).shape == (0,)


def test_a_large_object_close_by_is_not_expected_when_most_of_it_is_outside_the_image():
    """Its centre is in the image, but a detector sees what of it is in the picture: a bicycle
    0.6 m ahead spans twice the image's width; the same bicycle 3 m ahead, or a mug 0.6 m ahead,
    fits. A box reaching behind the camera is not in view at all."""
    view = camera_view()
    bicycle, mug = np.array([[0.35, 1.6, 1.0]]), np.array([[0.1, 0.1, 0.12]])
    config = VisibilityConfig()
    assert not should_be_visible(np.array([[0.6, 0.0, 0.8]]), bicycle, view, config)[0]
    assert should_be_visible(np.array([[3.0, 0.0, 0.8]]), bicycle, view, config)[0]
    assert should_be_visible(np.array([[0.6, 0.0, 0.9]]), mug, view, config)[0]
    assert not should_be_visible(np.array([[0.3, 0.0, 0.8]]), np.array([[1.0, 1.0, 1.0]]), view, config)[0]
    off = VisibilityConfig(in_image_share=0.0)  # only the centre, as before the share was asked
    assert should_be_visible(np.array([[0.6, 0.0, 0.8]]), bicycle, view, off)[0]
    np.testing.assert_allclose(in_image_shares(np.array([[3.0, 0.0, 1.0]]), mug, view), [1.0])
    with pytest.raises(ConfigurationError, match="in_image_share"):
        VisibilityConfig(in_image_share=1.5)
