"""Image and depth conversions: exact round trips, padded rows, and clear errors on bad input."""

from __future__ import annotations

import numpy as np
import pytest
from sensor_msgs.msg import Image

from merlin2_sailor.errors import InvalidInputError
from merlin2_sailor.ros.conversions import (
    array_to_image,
    camera_info_message,
    depth_to_metres,
    image_to_array,
    message_class,
    seconds_to_stamp,
    stamp_to_seconds,
)


@pytest.mark.parametrize(
    ("encoding", "shape", "dtype"),
    [("rgb8", (4, 5, 3), np.uint8), ("bgra8", (3, 2, 4), np.uint8), ("mono8", (4, 5), np.uint8),
     ("16UC1", (4, 5), np.uint16), ("32FC1", (4, 5), np.float32)],
)
def test_array_image_round_trip_is_exact(encoding: str, shape: tuple[int, ...], dtype: type) -> None:
    rng = np.random.default_rng(0)
    array = (rng.random(shape) * 200).astype(dtype)
    restored = image_to_array(array_to_image(array, encoding))
    assert restored.dtype == dtype
    np.testing.assert_array_equal(restored, array)


def test_padded_rows_and_big_endian_data_are_read_correctly() -> None:
    depth = np.array([[1000, 2000], [3000, 4000]], dtype=np.uint16)
    message = Image(height=2, width=2, encoding="16UC1", is_bigendian=1, step=6)
    rows = [depth[r].astype(">u2").tobytes() + b"\xff\xff" for r in range(2)]  # 2 padding bytes a row
    message.data = b"".join(rows)
    np.testing.assert_array_equal(image_to_array(message), depth)


@pytest.mark.parametrize(
    ("message", "reason"),
    [
        (Image(height=2, width=2, encoding="yuv422", step=4, data=bytes(8)), "not supported"),
        (Image(height=0, width=2, encoding="mono8", step=2, data=b""), "no pixels"),
        (Image(height=2, width=4, encoding="rgb8", step=4, data=bytes(8)), "smaller than a row"),
        (Image(height=2, width=2, encoding="rgb8", step=6, data=bytes(7)), "holds 7 bytes"),
    ],
)
def test_malformed_images_raise_invalid_input_with_the_reason(message: Image, reason: str) -> None:
    with pytest.raises(InvalidInputError, match=reason):
        image_to_array(message)


def test_array_that_does_not_fit_the_encoding_is_rejected() -> None:
    with pytest.raises(InvalidInputError, match="does not fit"):
        array_to_image(np.zeros((2, 2), dtype=np.uint8), "rgb8")
    with pytest.raises(InvalidInputError, match="dtype"):
        array_to_image(np.zeros((2, 2), dtype=np.float64), "32FC1")


def test_depth_units_follow_the_encoding_and_invalid_depths_become_nan() -> None:
    millimetres = np.array([[0, 1500], [65535, 250]], dtype=np.uint16)
    np.testing.assert_allclose(depth_to_metres(millimetres, "16UC1"), [[np.nan, 1.5], [65.535, 0.25]])
    metres = np.array([[np.inf, -1.0], [np.nan, 2.5]], dtype=np.float32)
    np.testing.assert_allclose(depth_to_metres(metres, "32FC1"), [[np.nan, np.nan], [np.nan, 2.5]])
    with pytest.raises(InvalidInputError, match="depth encoding"):
        depth_to_metres(millimetres, "rgb8")


def test_stamps_convert_both_ways_without_losing_nanoseconds() -> None:
    stamp = seconds_to_stamp(1234.999999999)
    assert (stamp.sec, stamp.nanosec) == (1234, 999999999)
    assert stamp_to_seconds(seconds_to_stamp(17.25)) == 17.25
    rounded_up = seconds_to_stamp(5.9999999999)
    assert (rounded_up.sec, rounded_up.nanosec) == (6, 0)


def test_camera_info_holds_the_pinhole_matrices() -> None:
    info = camera_info_message(640, 480, 500.0, 501.0, 320.0, 240.0)
    assert list(info.k) == [500.0, 0.0, 320.0, 0.0, 501.0, 240.0, 0.0, 0.0, 1.0]
    assert (info.width, info.height, list(info.d)) == (640, 480, [0.0] * 5)


def test_message_classes_are_found_by_type_name() -> None:
    assert message_class("sensor_msgs/msg/Image") is Image
    with pytest.raises(InvalidInputError, match="not installed"):
        message_class("sensor_msgs/msg/Nothing")
    with pytest.raises(InvalidInputError, match="like 'package/msg/Type'"):
        message_class("Image")
