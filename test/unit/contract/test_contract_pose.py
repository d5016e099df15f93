"""Rigid transforms: quaternions, composition, inversion and point mapping."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest

from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import InvalidInputError

QUARTER_TURN_ABOUT_Z = (0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4))


def test_quaternion_quarter_turn_about_z_maps_x_to_y() -> None:
    pose = Pose.from_quaternion(QUARTER_TURN_ABOUT_Z, (1.0, 2.0, 3.0))
    np.testing.assert_allclose(pose.transform_points(np.array([[1.0, 0.0, 0.0]])), [[1.0, 3.0, 3.0]], atol=1e-12)


def test_unnormalised_quaternion_is_normalised() -> None:
    scaled = Pose.from_quaternion(np.array(QUARTER_TURN_ABOUT_Z) * 7.0)
    np.testing.assert_allclose(scaled.rotation, Pose.from_quaternion(QUARTER_TURN_ABOUT_Z).rotation, atol=1e-12)


@pytest.mark.parametrize("seed", range(5))
def test_quaternion_round_trip_and_inverse(seed: int) -> None:
    rng = np.random.default_rng(seed)
    quaternion = rng.normal(size=4)
    quaternion /= np.linalg.norm(quaternion)
    quaternion *= np.sign(quaternion[3])
    pose = Pose.from_quaternion(quaternion, rng.normal(size=3))
    np.testing.assert_allclose(pose.quaternion_xyzw, quaternion, atol=1e-9)
    points = rng.normal(size=(10, 3))
    np.testing.assert_allclose(pose.inverse().transform_points(pose.transform_points(points)), points, atol=1e-12)
    np.testing.assert_allclose((pose @ pose.inverse()).matrix, np.eye(4), atol=1e-12)


def test_half_turn_quaternion_survives_the_round_trip() -> None:
    pose = Pose.from_quaternion((1.0, 0.0, 0.0, 0.0))  # 180 degrees about x, where w = 0
    np.testing.assert_allclose(np.abs(pose.quaternion_xyzw), [1.0, 0.0, 0.0, 0.0], atol=1e-12)


def test_compose_applies_the_right_transform_first() -> None:
    world_from_base = Pose.from_quaternion(QUARTER_TURN_ABOUT_Z, (10.0, 0.0, 0.0))
    base_from_camera = Pose(np.eye(3), (1.0, 0.0, 0.5))
    world_from_camera = world_from_base.compose(base_from_camera)
    # The camera origin is 1 m ahead of the base, which faces world +y from (10, 0, 0).
    np.testing.assert_allclose(world_from_camera.transform_points(np.zeros((1, 3))), [[10.0, 1.0, 0.5]], atol=1e-12)
    np.testing.assert_allclose(world_from_camera.matrix, world_from_base.matrix @ base_from_camera.matrix)


def test_from_matrix_round_trip() -> None:
    pose = Pose.from_quaternion((0.1, 0.2, 0.3, 0.9), (1.0, -2.0, 0.5))
    np.testing.assert_allclose(Pose.from_matrix(pose.matrix).matrix, pose.matrix, atol=1e-12)


def test_pose_arrays_are_read_only() -> None:
    pose = Pose.identity()
    with pytest.raises(ValueError):
        pose.translation[0] = 1.0


@pytest.mark.parametrize(
    "build",
    [
        lambda: Pose.from_quaternion((0.0, 0.0, 0.0, 0.0)),
        lambda: Pose.from_quaternion((0.0, 0.0, 1.0)),
        lambda: Pose(np.diag([1.0, 1.0, -1.0]), np.zeros(3)),  # a reflection, not a rotation
        lambda: Pose(np.eye(3) * 2.0, np.zeros(3)),
        lambda: Pose(np.eye(3), (0.0, np.nan, 0.0)),
        lambda: Pose.from_matrix(np.ones((4, 4))),
        lambda: Pose.identity().transform_points(np.zeros((2, 2))),
    ],
)
def test_invalid_poses_are_rejected(build: Callable[[], object]) -> None:
    with pytest.raises(InvalidInputError):
        build()
