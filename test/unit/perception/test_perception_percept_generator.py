"""Percepts from detections and an RGB-D frame; bad data becomes reasons, never exceptions."""

from __future__ import annotations

import numpy as np
import pytest

from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.perception.box3d import RejectionReason
from merlin2_sailor.perception.colour_histogram import colour_histogram, object_colour_similarity
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor.perception.percept_generator import PerceptGenerator, PerceptGeneratorConfig

from .scenes import MOTORCYCLE_BOX, RgbdScene, optical_camera_pose, wall_with_box_scene

OBJECT = (200, 150, 300, 330)


def coloured_image(height: int = 480, width: int = 640) -> np.ndarray:
    """An image whose every pixel encodes its own coordinates, so crops can be checked exactly."""
    rows, columns = np.mgrid[0:height, 0:width]
    return np.stack((rows % 256, columns % 256, (rows // 256) * 16 + columns // 256), axis=2).astype(np.uint8)


def detection(corners: tuple[float, float, float, float], tracker_id: str = "7", score: float = 0.9) -> Detection:
    return Detection(47, "cup", score, BoundingBox2D.from_corners(*corners), tracker_id=tracker_id)


def test_percepts_carry_detection_crop_geometry_and_stamp() -> None:
    depth, intrinsics = wall_with_box_scene(object_corners=OBJECT)
    image = coloured_image()
    generator = PerceptGenerator(PerceptGeneratorConfig(world_frame="odom"))
    batch = generator.generate(
        [detection(OBJECT)], image, depth, intrinsics, optical_camera_pose((1.0, 0.0, 0.5)), 12.5
    )
    assert batch.dropped == ()
    (percept,) = batch.percepts
    assert (percept.class_name, percept.class_id, percept.score, percept.tracker_id) == ("cup", 47, 0.9, "7")
    assert percept.stamp == 12.5 and percept.frame_id == "odom"
    np.testing.assert_array_equal(percept.crop, image[150:330, 200:300])
    assert percept.crop.dtype == np.uint8 and percept.crop.flags.owndata  # a copy, not a view of the frame
    assert percept.position[0] == pytest.approx(1.0 + 2.0, abs=1e-5)  # 2 m ahead of a camera at x = 1
    assert percept.size[1] == pytest.approx(100 / 525.0 * 2.0, rel=0.02)


def test_empty_tracker_id_stays_empty() -> None:
    depth, intrinsics = wall_with_box_scene(object_corners=OBJECT)
    batch = PerceptGenerator().generate(
        [detection(OBJECT, tracker_id="")], coloured_image(), depth, intrinsics, Pose.identity(), 1.0
    )
    assert batch.percepts[0].tracker_id == ""


def test_box_and_crop_are_clamped_to_the_image() -> None:
    depth, intrinsics = wall_with_box_scene(object_corners=(600, 400, 640, 480))
    image = coloured_image()
    batch = PerceptGenerator().generate(
        [detection((600.0, 400.0, 700.0, 520.0))], image, depth, intrinsics, Pose.identity(), 0.0
    )
    (percept,) = batch.percepts
    assert percept.box.corners == (600.0, 400.0, 640.0, 480.0)
    np.testing.assert_array_equal(percept.crop, image[400:480, 600:640])


def test_bad_detections_are_dropped_with_reasons_and_good_ones_kept() -> None:
    depth, intrinsics = wall_with_box_scene(object_corners=OBJECT)
    depth[0:100, 0:100] = np.nan
    detections = [detection(OBJECT), detection((-50.0, -50.0, -1.0, -1.0)), detection((10.0, 10.0, 90.0, 90.0))]
    batch = PerceptGenerator().generate(detections, coloured_image(), depth, intrinsics, Pose.identity(), 0.0)
    assert len(batch.percepts) == 1
    assert [
        (dropped.detection is detections[i], dropped.reason) for i, dropped in zip((1, 2), batch.dropped, strict=True)
    ] == [
        (True, RejectionReason.OUTSIDE_IMAGE),
        (True, RejectionReason.TOO_FEW_DEPTH_PIXELS),
    ]


@pytest.mark.parametrize(
    "change",
    [
        "depth_size",
        "intrinsics_size",
        "grey_image",
        "float_image",
        "nan_stamp",
        "all_nan_depth",
    ],
)
def test_unusable_frames_drop_every_detection(change: str) -> None:
    depth, intrinsics = wall_with_box_scene(object_corners=OBJECT)
    image, stamp = coloured_image(), 3.0
    if change == "depth_size":
        depth = depth[:240, :320]
    elif change == "intrinsics_size":
        intrinsics = CameraIntrinsics(525.0, 525.0, 319.5, 239.5, 1280, 720)
    elif change == "grey_image":
        image = image[:, :, 0]
    elif change == "float_image":
        image = image.astype(np.float32)
    elif change == "nan_stamp":
        stamp = float("nan")
    elif change == "all_nan_depth":
        depth = np.full_like(depth, np.nan)
    detections = [detection(OBJECT), detection((0.0, 0.0, 50.0, 50.0))]
    batch = PerceptGenerator().generate(detections, image, depth, intrinsics, Pose.identity(), stamp)
    assert batch.percepts == ()
    assert len(batch.dropped) == 2
    expected = RejectionReason.TOO_FEW_DEPTH_PIXELS if change == "all_nan_depth" else RejectionReason.INVALID_FRAME
    assert {dropped.reason for dropped in batch.dropped} == {expected}
    assert all(dropped.detail for dropped in batch.dropped)


def test_no_detections_gives_an_empty_batch() -> None:
    depth, intrinsics = wall_with_box_scene()
    batch = PerceptGenerator().generate([], coloured_image(), depth, intrinsics, Pose.identity(), 0.0)
    assert batch.percepts == () and batch.dropped == ()


def test_point_cloud_input_matches_depth_input(motorcycle_scene: RgbdScene) -> None:
    scene = motorcycle_scene
    pose = optical_camera_pose((2.0, -1.0, 0.8))
    found = Detection(4, "motorcycle", 0.95, MOTORCYCLE_BOX, tracker_id="3")
    generator = PerceptGenerator()
    from_depth = generator.generate([found], scene.image, scene.depth, scene.intrinsics, pose, 5.0)
    cloud = scene.intrinsics.back_project_image(scene.depth)
    from_cloud = generator.generate_from_points([found], scene.image, cloud, pose, 5.0)
    (a,), (b,) = from_depth.percepts, from_cloud.percepts
    np.testing.assert_allclose(a.position, b.position, atol=1e-5)
    np.testing.assert_allclose(a.size, b.size, atol=1e-5)
    np.testing.assert_array_equal(a.crop, b.crop)
    # A band on the distance from the sensor trims the ends of this wide, off-axis object.
    (by_range,) = generator.generate_from_points([found], scene.image, cloud, pose, 5.0, depth_axis=None).percepts
    assert by_range.size[1] < a.size[1] - 0.05
    bad = generator.generate_from_points([found], scene.image, cloud[:, :, :2], pose, 5.0)
    assert bad.dropped[0].reason is RejectionReason.INVALID_FRAME


def test_config_needs_a_world_frame() -> None:
    with pytest.raises(ConfigurationError):
        PerceptGeneratorConfig(world_frame="")


def test_the_colour_is_read_from_the_objects_own_pixels_not_the_wall_its_box_also_covers() -> None:
    """A green object 2 m away inside a box that also covers the red wall 4 m behind it: the box's
    colour would be mostly red, the object's is green."""
    inner = (230, 200, 270, 280)
    depth, intrinsics = wall_with_box_scene(object_corners=inner)
    image = np.zeros((480, 640, 3), dtype=np.uint8)
    image[:] = (200, 30, 30)
    image[200:280, 230:270] = (30, 200, 30)
    batch = PerceptGenerator().generate([detection(OBJECT)], image, depth, intrinsics, Pose.identity(), 0.0)
    (percept,) = batch.percepts
    expected = colour_histogram(np.array([[[30, 200, 30]]], dtype=np.uint8))
    np.testing.assert_allclose(percept.colour, expected, atol=1e-6)
    # The crop as a whole is mostly the red wall: its colour shares little with the object's.
    assert object_colour_similarity(percept.colour, colour_histogram(percept.crop)) < 0.25
