"""Rendered depth matches the geometry; the z-buffer occludes; the sensor's range and noise apply."""

from __future__ import annotations

import numpy as np
import pytest

from merlin2_sailor_demos.world.world import World

from .worlds import mug, room_world

# The robot stands at (1, 4) facing +x in a room 8 m wide; the camera is 0.1 m ahead, 1 m up: the wall
# at x = 5 is 3.9 m away, and the side walls are out of the field of view in front of it.
CAMERA_X = 1.1
ROBOT_Y = 4.0
FOCAL = 525.0
CENTRE_ROW = 239.5


def _world(objects=(), size=(5.0, 8.0), **options) -> World:
    return World(room_world(objects=objects, size=size, start=(1.0, ROBOT_Y, 0.0), **options), seed=0)


def _sigma(depth: float) -> float:
    return 0.001 + 0.0015 * depth**2


def test_the_wall_ahead_is_at_its_distance_on_every_pixel() -> None:
    frame = _world().render()
    wall = frame.true_depth[150:330, :]  # rows around the horizon see only the far wall
    np.testing.assert_allclose(wall, 5.0 - CAMERA_X, atol=1e-4)
    np.testing.assert_allclose(frame.depth[150:330, :], 5.0 - CAMERA_X, atol=1e-4)  # noise off in this world


def test_the_floor_depth_follows_the_row() -> None:
    frame = _world().render()
    for row in (400, 440, 479):
        expected = 1.0 * FOCAL / (row - CENTRE_ROW)  # camera 1 m above the floor, level
        np.testing.assert_allclose(frame.true_depth[row, 300:340], expected, rtol=1e-4)


def test_depth_noise_grows_with_distance_within_its_sigma() -> None:
    sensor = {"noise_base": 0.001, "noise_quadratic": 0.0015, "dropout": 0.0}
    frame = _world(depth_sensor=sensor).render()
    error = frame.depth[150:330, :] - frame.true_depth[150:330, :]
    sigma = _sigma(5.0 - CAMERA_X)
    assert np.std(error) == pytest.approx(sigma, rel=0.05)
    assert abs(np.mean(error)) < sigma / 10
    row = 470  # the floor 2.28 m ahead
    near = frame.depth[row, :] - frame.true_depth[row, :]
    assert np.std(near) == pytest.approx(_sigma(FOCAL / (row - CENTRE_ROW)), rel=0.15)


def test_an_object_occludes_the_wall_and_owns_its_pixels() -> None:
    world = _world([mug("box", 3.5, ROBOT_Y)])  # 0.3 m cube on the floor, front face at x = 3.35
    frame = world.render()
    front = 3.35 - CAMERA_X
    top_row = CENTRE_ROW + (1.0 - 0.3) * FOCAL / front
    bottom_row = CENTRE_ROW + 1.0 * FOCAL / front
    rows = slice(int(np.ceil(top_row)) + 1, int(np.floor(bottom_row)))
    np.testing.assert_allclose(frame.true_depth[rows, 318:322], front, atol=1e-3)
    assert np.all(frame.instance[rows, 318:322] == 0)
    assert np.all(frame.instance[150:330, :] == -1)  # above the object: the wall
    wall_color = frame.color[200, 320].astype(int)
    assert np.abs(frame.color[rows, 318:322].astype(int) - wall_color).max() > 40  # textured by its photo


def test_a_tall_object_hides_the_one_behind_it() -> None:
    world = _world([mug("front", 3.0, ROBOT_Y, size=(0.3, 0.6, 1.3)), mug("behind", 4.0, ROBOT_Y)])
    frame = world.render()
    assert np.count_nonzero(frame.instance == 1) == 0
    assert [seen.index for seen in world.visible_objects(frame)] == [0]
    assert world.detect(frame) and all(d.box.width > 50 for d in world.detect(frame))


def test_depth_outside_the_sensor_range_is_invalid() -> None:
    world = _world([mug("close", 1.3, ROBOT_Y, size=(0.1, 0.1, 1.5))], size=(8.0, 8.0))  # wall 6.9 m, object 0.15 m
    frame = world.render()
    assert np.all(frame.true_depth[150:200, :100] > 6.0)
    assert np.all(np.isnan(frame.depth[150:200, :100]))  # beyond 6 m
    assert np.all(frame.true_depth[200:280, 300:340] < 0.3)
    assert np.all(np.isnan(frame.depth[200:280, 300:340]))  # nearer than 0.3 m
    assert not np.any(np.isnan(frame.depth[460:, :60]))  # the floor beside the object is measured


def test_a_red_mug_looks_red() -> None:
    description = room_world(objects=[mug("red", 2.5, 2.0) | {"texture": "red"}], size=(5.0, 4.0),
                             textures={"red": {"photo": "skimage/coffee", "crop": [173, 13, 411, 239],
                                               "recolor": [205, 28, 32]}})
    frame = World(description).render()
    pixels = frame.color[frame.instance == 0].astype(int)
    assert len(pixels) > 200
    assert np.mean(pixels[:, 0] - pixels[:, 1]) > 40
