"""The geometry behind the replays: view synthesis, depth registration, ground plane, odometry."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor.perception.percept_generator import PerceptGenerator
from merlin2_sailor_demos.replay.depth_registration import DepthCamera, register_depth
from merlin2_sailor_demos.replay.ground_plane import GroundPlaneCamera, foot_point, ground_depth, standing_depth
from merlin2_sailor_demos.replay.view_synthesis import background_fill_columns, translate_view
from merlin2_sailor_demos.replay.visual_odometry import VisualOdometry
from merlin2_sailor_demos.replay.vtest import BOARD_DEPTH_BAND

# --- view synthesis -------------------------------------------------------------------------


def test_background_fill_takes_the_farther_neighbour_and_leaves_known_pixels() -> None:
    known = np.array([[True, False, False, True, False]])
    depth = np.array([[1.0, 0.0, 0.0, 5.0, 0.0]])
    assert background_fill_columns(known, depth).tolist() == [[0, 3, 3, 3, 3]]
    assert background_fill_columns(np.zeros((1, 3), bool), np.zeros((1, 3))).tolist() == [[-1, -1, -1]]


def test_a_sideways_step_shifts_each_pixel_by_its_parallax_and_the_nearest_wins() -> None:
    color = np.zeros((4, 40, 3), dtype=np.uint8)
    color[:, :, 0] = np.arange(40, dtype=np.uint8)  # each column its own value
    depth = np.full((4, 40), 2.0, dtype=np.float32)
    depth[:, 20:24] = 1.0  # a nearer post: twice the parallax
    new_color, new_depth = translate_view(color, depth, focal_pixels=100.0, shift_metres=0.1)
    # Background: 100 * 0.1 / 2 = 5 px to the left; the post: 10 px.
    assert new_color[0, 0, 0] == 5 and new_color[0, 5, 0] == 10
    assert new_color[0, 10:14, 0].tolist() == [20, 21, 22, 23] and np.all(new_depth[:, 10:14] == 1.0)
    # Background columns 15..18 land under the post and are hidden. Nothing lands on 15..18 (the
    # post moved away from there): filled from the background beside them, depth unknown.
    assert new_depth[0, 14] == 2.0 and new_color[0, 14, 0] == 19
    assert np.isnan(new_depth[0, 15:19]).all() and new_color[0, 15:19, 0].tolist() == [19] * 4
    assert np.isnan(new_depth[0, 35:]).all()  # nothing came into view from the right
    same_color, same_depth = translate_view(color, depth, 100.0, 0.0)
    assert np.array_equal(same_color, color) and np.array_equal(same_depth, depth)


# --- depth registration ---------------------------------------------------------------------


def test_registering_depth_through_an_identity_transform_gives_it_back_in_metres() -> None:
    raw = np.full((30, 40), 8000, dtype=np.uint16)  # 1 m at 1/8 mm per unit
    raw[10:20, 10:20] = 4000
    raw[25:, :] = 0  # no measurement: stays unknown, and so does the crack across column 5
    raw[:, 5] = 0
    camera = DepthCamera(50.0, 50.0, 19.5, 14.5, metres_per_unit=0.000125)
    color = CameraIntrinsics(50.0, 50.0, 19.5, 14.5, 40, 30)
    registered = register_depth(raw, camera, Pose.identity(), color)
    assert np.isnan(registered[25:]).all()
    assert np.allclose(registered[:25, 5], 1.0)  # a one-pixel crack takes its neighbours' depth
    assert np.allclose(registered[:25, :5], raw[:25, :5] * 0.000125)
    assert np.allclose(registered[:25, 6:], raw[:25, 6:] * 0.000125)


def test_registering_depth_from_a_camera_beside_the_colour_one_moves_it_by_the_parallax() -> None:
    raw = np.full((30, 60), 8000, dtype=np.uint16)  # a wall 1 m away
    camera = DepthCamera(50.0, 50.0, 29.5, 14.5, metres_per_unit=0.000125)
    # The depth camera sits 4 cm to the right of the colour camera: the wall's points move 2 px right.
    color_from_depth = Pose(np.eye(3), np.array([0.04, 0.0, 0.0]))
    registered = register_depth(raw, camera, color_from_depth, CameraIntrinsics(50.0, 50.0, 29.5, 14.5, 60, 30))
    assert np.isnan(registered[:, :2]).all() and np.allclose(registered[:, 2:], 1.0)


def test_the_depth_lens_model_leaves_the_principal_point_and_bends_the_corners() -> None:
    raw = np.full((3, 3), 1000, dtype=np.uint16)
    plain = DepthCamera(1.0, 1.0, 1.0, 1.0, 0.001)
    distorted = DepthCamera(1.0, 1.0, 1.0, 1.0, 0.001, (0.2, 0.0, 0.0, 0.0, 0.0))
    straight, _ = plain.back_project(raw)
    bent, _ = distorted.back_project(raw)
    assert np.allclose(bent[4], straight[4])  # the centre pixel
    assert bent[0, 0] == pytest.approx(straight[0, 0] * (1 + 0.2 * 2))  # a corner at r^2 = 2
    with pytest.raises(ConfigurationError):
        DepthCamera(1.0, 1.0, 0.0, 0.0, 0.001, (0.1, 0.2))


# --- ground plane ---------------------------------------------------------------------------

GROUND = GroundPlaneCamera(height=8.0, pitch_degrees=34.0, horizontal_field_of_view_degrees=60.0)


def test_the_optical_axis_meets_the_ground_where_height_and_pitch_say() -> None:
    intrinsics = GROUND.intrinsics(768, 576)
    assert intrinsics.fx == pytest.approx(384 / math.tan(math.radians(30)))
    pose = GROUND.camera_to_world()
    depth = ground_depth(GROUND, intrinsics, pose)
    # The principal point (383.5, 287.5) lies between four pixels; their mean is the axis' depth.
    assert depth[287:289, 383:385].mean() == pytest.approx(8.0 / math.sin(math.radians(34)), rel=1e-3)
    assert np.all(np.diff(depth[:, 384]) < 0)  # lower rows see nearer ground
    foot = foot_point(BoundingBox2D.from_corners(374.0, 200.0, 394.0, 288.0), intrinsics, pose)
    assert foot is not None
    assert foot == pytest.approx([8.0 / math.tan(math.radians(34)), 0.0, 0.0], abs=1e-6)


def test_a_standing_box_becomes_an_upright_percept_on_its_foot_point() -> None:
    intrinsics = GROUND.intrinsics(768, 576)
    pose = GROUND.camera_to_world()
    distance = 8.0 / math.tan(math.radians(34))
    # A person 1.75 m tall whose feet are at the image centre: project their head to get the box.
    head = pose.inverse().transform_points(np.array([[distance, 0.0, 1.75]]))
    (head_pixel,), _ = intrinsics.project(head)
    box = BoundingBox2D.from_corners(374.0, float(head_pixel[1]) + 0.5, 394.0, 288.0)
    depth = standing_depth([box], ground_depth(GROUND, intrinsics, pose), GROUND, intrinsics, pose)
    batch = PerceptGenerator(_board_config()).generate(
        [Detection(1, "person", 0.9, box)], np.zeros((576, 768, 3), np.uint8), depth, intrinsics, pose, 0.0)
    (percept,) = batch.percepts
    assert percept.position[0] == pytest.approx(distance, abs=0.05)
    assert percept.position[2] == pytest.approx(1.75 / 2, abs=0.05)
    assert percept.size[2] == pytest.approx(1.75, abs=0.05)


def test_a_box_standing_above_the_horizon_gets_no_depth() -> None:
    camera = GroundPlaneCamera(height=2.0, pitch_degrees=5.0, horizontal_field_of_view_degrees=90.0)
    intrinsics = camera.intrinsics(200, 200)
    pose = camera.camera_to_world()
    depth = ground_depth(camera, intrinsics, pose)
    assert np.isnan(depth[0]).all()
    box = BoundingBox2D.from_corners(90.0, 10.0, 110.0, 40.0)
    assert foot_point(box, intrinsics, pose) is None
    painted = standing_depth([box], depth, camera, intrinsics, pose)
    assert np.array_equal(np.isnan(painted), np.isnan(depth))
    with pytest.raises(ConfigurationError):
        GroundPlaneCamera(height=2.0, pitch_degrees=95.0, horizontal_field_of_view_degrees=60.0)


def _board_config():
    from merlin2_sailor.perception.box3d import Box3DConfig
    from merlin2_sailor.perception.percept_generator import PerceptGeneratorConfig

    return PerceptGeneratorConfig(box3d=Box3DConfig(depth_band_half_width=BOARD_DEPTH_BAND, maximum_depth=60.0))


# --- visual odometry ------------------------------------------------------------------------


def test_odometry_recovers_a_sideways_step_in_front_of_a_textured_wall() -> None:
    rng = np.random.default_rng(1)
    texture = cv2.GaussianBlur(rng.integers(0, 255, (520, 680), dtype=np.uint8), (5, 5), 0)
    texture = cv2.equalizeHist(texture)
    intrinsics = CameraIntrinsics(500.0, 500.0, 319.5, 239.5, 640, 480)
    depth = np.full((480, 640), 1.5, dtype=np.float32)
    first = texture[20:500, 20:660]
    second = texture[20:500, 32:672]  # the wall moved 12 px left: the camera moved right
    odometry = VisualOdometry(intrinsics)
    assert odometry.step(first, depth).current_from_previous.translation == pytest.approx(np.zeros(3))
    step = odometry.step(second, depth)
    assert not step.lost and step.inliers >= 30
    # current_from_previous maps the wall's points 12 * 1.5 / 500 = 3.6 cm to the left.
    assert step.current_from_previous.translation == pytest.approx([-0.036, 0.0, 0.0], abs=0.004)
    lost = odometry.step(np.zeros((480, 640), np.uint8), depth)
    assert lost.lost and np.allclose(lost.current_from_previous.matrix, np.eye(4))
