"""Pinhole intrinsics, back-projection, projection and the frustum test."""

from __future__ import annotations

import numpy as np
import pytest

from merlin2_sailor.contract.camera import CameraIntrinsics, FrustumLimits, points_in_frustum
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import ConfigurationError, InvalidInputError


def optical_camera_pose(position: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> Pose:
    """A camera at ``position`` looking along the world's +x (REP 103 optical axes)."""
    rotation = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    return Pose(rotation, np.asarray(position, dtype=np.float64))

INTRINSICS = CameraIntrinsics(fx=500.0, fy=400.0, cx=320.0, cy=240.0, width=640, height=480)


def test_from_k_reads_a_camera_info_matrix() -> None:
    intrinsics = CameraIntrinsics.from_k([500.0, 0.0, 320.0, 0.0, 400.0, 240.0, 0.0, 0.0, 1.0], 640, 480)
    assert intrinsics == INTRINSICS
    np.testing.assert_allclose(intrinsics.k.reshape(-1), [500.0, 0.0, 320.0, 0.0, 400.0, 240.0, 0.0, 0.0, 1.0])


def test_back_projection_follows_the_optical_frame() -> None:
    # Right of and below the principal point means +x and +y (x right, y down, z forward).
    point = INTRINSICS.back_project(np.array(420.0), np.array(280.0), np.array(2.0))
    np.testing.assert_allclose(point, [0.4, 0.2, 2.0])


def test_projection_inverts_back_projection() -> None:
    rng = np.random.default_rng(0)
    columns, rows, depth = rng.uniform(0, 640, 50), rng.uniform(0, 480, 50), rng.uniform(0.3, 9.0, 50)
    pixels, projected_depth = INTRINSICS.project(INTRINSICS.back_project(columns, rows, depth))
    np.testing.assert_allclose(pixels, np.stack((columns, rows), axis=1), atol=1e-9)
    np.testing.assert_allclose(projected_depth, depth)


def test_points_behind_the_camera_do_not_project() -> None:
    pixels, _ = INTRINSICS.project(np.array([[0.0, 0.0, -1.0], [0.0, 0.0, 0.0]]))
    assert np.isnan(pixels).all()


def test_back_project_image_gives_an_organised_cloud() -> None:
    depth = np.full((480, 640), 3.0)
    cloud = INTRINSICS.back_project_image(depth)
    assert cloud.shape == (480, 640, 3)
    np.testing.assert_allclose(cloud[240, 320], [0.0, 0.0, 3.0])
    np.testing.assert_allclose(cloud[0, 0], [-320.0 / 500.0 * 3.0, -240.0 / 400.0 * 3.0, 3.0])
    with pytest.raises(InvalidInputError):
        INTRINSICS.back_project_image(np.ones((10, 10)))


def test_frustum_in_a_world_with_the_camera_looking_along_x() -> None:
    pose = optical_camera_pose((1.0, 0.0, 1.0))
    points = np.array(
        [
            [4.0, 0.0, 1.0],  # straight ahead, 3 m
            [0.0, 0.0, 1.0],  # behind
            [4.0, 10.0, 1.0],  # far to the left, outside the field of view
            [20.0, 0.0, 1.0],  # beyond the far limit
            [1.1, 0.0, 1.0],  # closer than the near limit
            [4.0, -1.0, 0.0],  # ahead, right and below: inside
        ]
    )
    inside = points_in_frustum(INTRINSICS, pose, points, FrustumLimits(near=0.2, far=8.0))
    assert inside.tolist() == [True, False, False, False, False, True]


def test_frustum_margin_excludes_the_border() -> None:
    # A point projecting 5 px inside the left border.
    point = INTRINSICS.back_project(np.array(4.5), np.array(240.0), np.array(2.0))[np.newaxis]
    identity = optical_camera_pose().compose(optical_camera_pose().inverse())
    assert points_in_frustum(INTRINSICS, identity, point, FrustumLimits(margin=0.0))[0]
    assert not points_in_frustum(INTRINSICS, identity, point, FrustumLimits(margin=10.0))[0]


@pytest.mark.parametrize(
    "arguments",
    [
        dict(fx=0.0, fy=1.0, cx=0.0, cy=0.0, width=10, height=10),
        dict(fx=1.0, fy=1.0, cx=float("nan"), cy=0.0, width=10, height=10),
        dict(fx=1.0, fy=1.0, cx=0.0, cy=0.0, width=0, height=10),
    ],
)
def test_invalid_intrinsics_are_rejected(arguments: dict) -> None:
    with pytest.raises(InvalidInputError):
        CameraIntrinsics(**arguments)


def test_invalid_k_and_limits_are_rejected() -> None:
    with pytest.raises(InvalidInputError):
        CameraIntrinsics.from_k([1.0, 0.5, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0], 10, 10)
    with pytest.raises(InvalidInputError):
        CameraIntrinsics.from_k([1.0, 0.0, 0.0], 10, 10)
    with pytest.raises(ConfigurationError):
        FrustumLimits(near=5.0, far=1.0)
