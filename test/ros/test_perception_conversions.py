"""Perception messages <-> core objects: exact round trips, and clear errors on malformed messages."""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np
import pytest
from geometry_msgs.msg import TransformStamped
from nav_msgs.msg import Odometry
from scipy.spatial.transform import Rotation
from sensor_msgs.msg import CameraInfo, PointField
from std_msgs.msg import Header
from visualization_msgs.msg import Marker

from merlin2_sailor.contract.percept import BoundingBox2D, Percept
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import InvalidInputError
from merlin2_sailor.perception.colour_histogram import COLOUR_BINS
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor.ros.conversions import (
    array_to_image,
    array_to_point_cloud,
    camera_info_message,
    camera_info_to_intrinsics,
    detection_from_message,
    detections_from_message,
    detections_to_message,
    image_to_rgb,
    mask_from_message,
    mask_to_message,
    odometry_to_camera_pose,
    percept_markers,
    percepts_from_message,
    percepts_to_message,
    point_cloud_to_array,
    pose_from_message,
    pose_to_message,
    seconds_to_stamp,
    transform_to_pose,
)
from merlin2_sailor_interfaces.msg import Detection as DetectionMessage
from merlin2_sailor_interfaces.msg import DetectionArray, Mask, PerceptArray, Point2D


def make_percept(crop_shape: tuple[int, int] = (4, 6), **changes: object) -> Percept:
    rng = np.random.default_rng(1)
    fields: dict[str, object] = {
        "class_name": "cup", "score": 0.83, "box": BoundingBox2D(120.5, 80.25, 60.0, 40.0),
        "position": np.array([2.5, -0.75, 0.9]), "size": np.array([0.08, 0.09, 0.12]),
        "stamp": 1712.125, "crop": rng.integers(0, 256, (*crop_shape, 3), dtype=np.uint8),
        "tracker_id": "cam_7", "class_id": 47, "frame_id": "map",
    }
    fields.update(changes)
    return Percept(**fields)  # type: ignore[arg-type]


# --- detections ---------------------------------------------------------------------------------


def test_detection_array_round_trip_keeps_every_field_and_the_image_header() -> None:
    mask = np.zeros((50, 60), dtype=bool)
    mask[10:30, 20:45] = True
    detections = [
        Detection(62, "chair", 0.91, BoundingBox2D(40.5, 30.0, 21.0, 11.5), tracker_id="3"),
        Detection(1, "person", 0.42, BoundingBox2D.from_corners(20.0, 10.0, 45.0, 30.0), mask=mask),
    ]
    header = Header(stamp=seconds_to_stamp(12.5), frame_id="camera_color_optical_frame")
    message = detections_to_message(detections, header)
    assert message.header == header and message.detections[1].mask.width == 60
    restored = detections_from_message(message)
    for original, copy in zip(detections, restored, strict=True):
        assert (copy.class_id, copy.class_name, copy.score, copy.box, copy.tracker_id) == (
            original.class_id, original.class_name, original.score, original.box, original.tracker_id)
    assert restored[0].mask is None
    np.testing.assert_array_equal(restored[1].mask, mask)  # a rectangle survives the polygon exactly


def test_a_curved_mask_survives_its_polygon_within_a_few_pixels() -> None:
    rows, columns = np.mgrid[0:80, 0:100]
    disc = (rows - 40) ** 2 + (columns - 50) ** 2 <= 25**2
    restored = mask_from_message(mask_to_message(disc))
    assert restored is not None
    intersection, union = np.count_nonzero(restored & disc), np.count_nonzero(restored | disc)
    assert intersection / union > 0.97


def _detection_message(**changes: object) -> DetectionMessage:
    message = DetectionMessage(class_id=3, class_name="car", score=0.7)
    message.bbox.center.position.x, message.bbox.center.position.y = 50.0, 40.0
    message.bbox.size.x, message.bbox.size.y = 20.0, 10.0
    for path, value in changes.items():
        target = message
        *parents, leaf = path.split("__")
        for parent in parents:
            target = getattr(target, parent)
        setattr(target, leaf, value)
    return message


@pytest.mark.parametrize(
    ("changes", "reason"),
    [
        ({"class_name": ""}, "no class_name"),
        ({"score": 1.5}, "not in \\[0, 1\\]"),
        ({"score": math.nan}, "not in \\[0, 1\\]"),
        ({"bbox__center__position__x": math.inf}, "non-finite box"),
        ({"bbox__size__y": 0.0}, "empty box"),
        ({"bbox__size__x": -4.0}, "empty box"),
        ({"bbox__center__theta": 0.3}, "rotated box"),
        ({"mask": Mask(height=10, width=10, data=[Point2D(x=1.0, y=1.0), Point2D(x=5.0, y=1.0)])},
         "at least 3 finite vertices"),
        ({"mask": Mask(height=0, width=0, data=[Point2D(x=1.0, y=1.0)] * 3)}, "image of 0x0"),
    ],
)
def test_malformed_detections_raise_invalid_input_with_the_reason(changes: dict, reason: str) -> None:
    with pytest.raises(InvalidInputError, match=reason):
        detection_from_message(_detection_message(**changes))
    with pytest.raises(InvalidInputError, match=reason):
        detections_from_message(DetectionArray(detections=[_detection_message(), _detection_message(**changes)]))


def test_a_well_formed_detection_message_is_accepted() -> None:
    detection = detection_from_message(_detection_message())
    assert detection.box.corners == (40.0, 35.0, 60.0, 45.0) and detection.tracker_id == ""


# --- percepts -----------------------------------------------------------------------------------


def test_percept_array_round_trip_keeps_every_field_and_the_crop() -> None:
    colour = np.zeros(COLOUR_BINS, dtype=np.float32)
    colour[[3, 19]] = (0.25, 0.75)
    percepts = [dataclasses.replace(make_percept(), colour=colour),
                make_percept((0, 0), tracker_id="", class_name="dog")]
    header = Header(stamp=seconds_to_stamp(1712.125), frame_id="map")
    message = percepts_to_message(percepts, header)
    assert message.percepts[0].crop.encoding == "rgb8" and message.percepts[1].crop.width == 0
    restored = percepts_from_message(message)
    for original, copy in zip(percepts, restored, strict=True):
        for name in ("class_name", "score", "box", "tracker_id", "class_id", "frame_id"):
            assert getattr(copy, name) == getattr(original, name), name
        assert copy.stamp == pytest.approx(original.stamp, abs=1e-9)
        np.testing.assert_array_equal(copy.position, original.position)
        np.testing.assert_array_equal(copy.size, original.size)
        np.testing.assert_array_equal(copy.crop, original.crop)
        assert copy.crop.dtype == np.uint8 and copy.crop.shape[2:] == (3,)
    np.testing.assert_array_equal(restored[0].colour, colour)
    assert restored[1].colour is None


def test_percepts_of_another_frame_cannot_be_published_in_this_one() -> None:
    with pytest.raises(InvalidInputError, match="odom"):
        percepts_to_message([make_percept(frame_id="odom")], Header(frame_id="map"))


@pytest.mark.parametrize(
    ("mutate", "reason"),
    [
        (lambda m: setattr(m.percepts[0].position, "x", math.nan), "must be finite"),
        (lambda m: setattr(m.percepts[0].size, "z", -0.1), "non-negative"),
        (lambda m: setattr(m.percepts[0], "score", 2.0), "not in \\[0, 1\\]"),
        (lambda m: setattr(m.percepts[0], "crop", array_to_image(np.zeros((2, 2), np.uint8), "mono8")), "rgb8"),
        (lambda m: setattr(m.header, "frame_id", ""), "frame_id"),
        (lambda m: setattr(m.percepts[0], "colour", [0.5, 0.5]), "colour of 2 values"),
        (lambda m: setattr(m.percepts[0], "colour", [math.nan] * COLOUR_BINS), "summing to 1"),
        (lambda m: setattr(m.percepts[0], "colour", [0.5] * COLOUR_BINS), "summing to 1"),
    ],
)
def test_malformed_percepts_raise_invalid_input_with_the_reason(mutate, reason: str) -> None:
    message: PerceptArray = percepts_to_message([make_percept()], Header(frame_id="map"))
    mutate(message)
    with pytest.raises(InvalidInputError, match=reason):
        percepts_from_message(message)


def test_markers_clear_the_last_frame_then_draw_a_box_and_a_label_per_percept() -> None:
    header = Header(stamp=seconds_to_stamp(3.0), frame_id="map")
    markers = percept_markers([make_percept(), make_percept(size=np.zeros(3), tracker_id="")], header).markers
    assert markers[0].action == Marker.DELETEALL
    boxes = [marker for marker in markers if marker.type == Marker.CUBE]
    labels = [marker for marker in markers if marker.type == Marker.TEXT_VIEW_FACING]
    assert len(boxes) == len(labels) == 2
    assert all(marker.header.frame_id == "map" for marker in markers)
    assert (boxes[0].pose.position.x, boxes[0].scale.z) == pytest.approx((2.5, 0.12))
    assert min(boxes[1].scale.x, boxes[1].scale.y, boxes[1].scale.z) > 0.0  # RViz draws nothing at 0
    assert labels[0].text == "cup #cam_7 0.83" and labels[1].text == "cup 0.83"
    assert labels[0].pose.position.z > boxes[0].pose.position.z + boxes[0].scale.z / 2.0
    assert len({(marker.ns, marker.id) for marker in markers[1:]}) == 4


# --- images, intrinsics, poses, clouds ----------------------------------------------------------


@pytest.mark.parametrize(
    ("encoding", "channel_order", "alpha"),
    [("rgb8", [0, 1, 2], False), ("bgr8", [2, 1, 0], False), ("rgba8", [0, 1, 2], True), ("bgra8", [2, 1, 0], True)],
)
def test_colour_images_become_rgb_whatever_their_channel_order(encoding: str, channel_order: list[int],
                                                               alpha: bool) -> None:
    rgb = np.random.default_rng(2).integers(0, 256, (3, 4, 3), dtype=np.uint8)
    pixels = rgb[:, :, channel_order]
    if alpha:
        pixels = np.dstack([pixels, np.full((3, 4), 255, np.uint8)])
    np.testing.assert_array_equal(image_to_rgb(array_to_image(np.ascontiguousarray(pixels), encoding)), rgb)


@pytest.mark.parametrize("encoding", ["mono8", "16UC1", "32FC1"])
def test_images_a_detector_cannot_take_are_refused(encoding: str) -> None:
    dtype = {"mono8": np.uint8, "16UC1": np.uint16, "32FC1": np.float32}[encoding]
    with pytest.raises(InvalidInputError, match="cannot be fed to a detector"):
        image_to_rgb(array_to_image(np.zeros((2, 2), dtype=dtype), encoding))


def test_camera_info_gives_the_pinhole_intrinsics_and_size() -> None:
    intrinsics = camera_info_to_intrinsics(camera_info_message(741, 500, 994.978, 990.0, 311.193, 254.877))
    assert (intrinsics.fx, intrinsics.fy, intrinsics.cx, intrinsics.cy) == (994.978, 990.0, 311.193, 254.877)
    assert (intrinsics.width, intrinsics.height) == (741, 500)


@pytest.mark.parametrize(
    ("message", "reason"),
    [(CameraInfo(width=640, height=480), "no calibration"),  # all-zero K: an uncalibrated driver
     (camera_info_message(0, 480, 500.0, 500.0, 320.0, 240.0), "no image size")],
)
def test_unusable_camera_info_raises_invalid_input(message: CameraInfo, reason: str) -> None:
    with pytest.raises(InvalidInputError, match=reason):
        camera_info_to_intrinsics(message)


def test_pose_messages_round_trip_and_odometry_composes_the_extrinsics() -> None:
    rotation = Rotation.from_euler("zyx", [30.0, -10.0, 5.0], degrees=True)
    world_from_base = Pose(rotation.as_matrix(), [1.0, -2.0, 0.3])
    restored = pose_from_message(pose_to_message(world_from_base))
    np.testing.assert_allclose(restored.matrix, world_from_base.matrix, atol=1e-12)

    base_from_camera = Pose.from_quaternion([-0.5, 0.5, -0.5, 0.5], [0.2, 0.0, 1.1])
    odometry = Odometry(header=Header(frame_id="odom"), child_frame_id="base_link")
    odometry.pose.pose = pose_to_message(world_from_base)
    camera = odometry_to_camera_pose(odometry, base_from_camera)
    point_in_camera = np.array([0.1, -0.2, 2.0])
    expected = world_from_base.transform_points(base_from_camera.transform_points(point_in_camera))
    np.testing.assert_allclose(camera.transform_points(point_in_camera), expected, atol=1e-12)

    transform = TransformStamped()
    transform.transform.translation.x, transform.transform.translation.z = 1.0, -2.0
    transform.transform.rotation.z, transform.transform.rotation.w = math.sin(0.25), math.cos(0.25)
    np.testing.assert_allclose(transform_to_pose(transform).matrix,
                               Pose(Rotation.from_rotvec([0, 0, 0.5]).as_matrix(), [1.0, 0.0, -2.0]).matrix,
                               atol=1e-12)


@pytest.mark.parametrize("bad", [(math.nan, "x"), (0.0, "all")])
def test_nan_or_zero_quaternions_in_pose_messages_raise_invalid_input(bad: tuple[float, str]) -> None:
    message = pose_to_message(Pose.identity())
    value, field = bad
    if field == "all":
        message.orientation.x = message.orientation.y = message.orientation.z = message.orientation.w = 0.0
    else:
        message.position.x = value
    with pytest.raises(InvalidInputError):
        pose_from_message(message)


def test_organised_cloud_round_trip_keeps_nan_points() -> None:
    points = np.random.default_rng(3).normal(size=(4, 5, 3)).astype(np.float32)
    points[1, 2] = np.nan
    message = array_to_point_cloud(points, Header(frame_id="camera_color_optical_frame"))
    assert not message.is_dense
    np.testing.assert_array_equal(point_cloud_to_array(message), points)


def test_cloud_with_padding_extra_fields_and_float64_is_read() -> None:
    points = np.arange(2 * 3 * 3, dtype=np.float64).reshape(2, 3, 3)
    layout = np.dtype({"names": ["rgb", "x", "y", "z"], "formats": ["<f4", "<f8", "<f8", "<f8"],
                       "offsets": [0, 8, 16, 24], "itemsize": 40})
    records = np.zeros((2, 3), dtype=layout)
    records["x"], records["y"], records["z"] = points[..., 0], points[..., 1], points[..., 2]
    rows = [records[row].tobytes() + b"\0" * 8 for row in range(2)]  # 8 padding bytes a row
    message = array_to_point_cloud(np.zeros((2, 3, 3), np.float32))
    message.fields = [PointField(name="rgb", offset=0, datatype=PointField.FLOAT32, count=1)] + [
        PointField(name=name, offset=8 * (index + 1), datatype=PointField.FLOAT64, count=1)
        for index, name in enumerate("xyz")]
    message.point_step, message.row_step, message.data = 40, 128, b"".join(rows)
    np.testing.assert_array_equal(point_cloud_to_array(message), points.astype(np.float32))


@pytest.mark.parametrize(
    ("mutate", "reason"),
    [
        (lambda m: setattr(m, "height", 1), "not organised"),
        (lambda m: setattr(m, "fields", m.fields[:2]), "no field\\(s\\) z"),
        (lambda m: setattr(m.fields[0], "datatype", PointField.UINT16), "FLOAT32 or FLOAT64"),
        (lambda m: setattr(m, "point_step", 8), "do not fit"),
        (lambda m: setattr(m, "row_step", 12), "shorter than"),
        (lambda m: setattr(m, "data", bytes(10)), "holds 10 bytes"),
    ],
)
def test_malformed_clouds_raise_invalid_input_with_the_reason(mutate, reason: str) -> None:
    message = array_to_point_cloud(np.zeros((4, 5, 3), dtype=np.float32))
    mutate(message)
    with pytest.raises(InvalidInputError, match=reason):
        point_cloud_to_array(message)


def test_a_mask_vertex_far_outside_the_image_rasterises_like_one_at_its_edge() -> None:
    far = Mask(height=10, width=10, data=[Point2D(x=2.0, y=2.0), Point2D(x=1e15, y=2.0), Point2D(x=2.0, y=7.0)])
    near = Mask(height=10, width=10, data=[Point2D(x=2.0, y=2.0), Point2D(x=9.0, y=2.0), Point2D(x=2.0, y=7.0)])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no invalid cast to int32
        raster = mask_from_message(far)
    assert raster[2, 2:].all() and raster[6, 2] and not raster[8].any()
    assert raster.sum() > mask_from_message(near).sum()
