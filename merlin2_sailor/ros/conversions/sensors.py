"""Images, depth, camera intrinsics and stamps: sensor messages to NumPy and back.

cv_bridge is not installable from PyPI (its PyPI namesake is an old ROS 1 copy that breaks on
NumPy 2), so images are converted here with NumPy alone. Conversions validate what they read:
a malformed message raises InvalidInputError with the reason, which a node logs before dropping
the message, never a crash deep inside an algorithm.
"""

from __future__ import annotations

import numpy as np
from builtin_interfaces.msg import Time
from sensor_msgs.msg import CameraInfo, Image
from std_msgs.msg import Header

from merlin2_sailor.errors import InvalidInputError
from merlin2_sailor.perception.depth import depth_to_metres  # noqa: F401 - re-exported for nodes

# encoding -> (dtype, channels)
IMAGE_ENCODINGS: dict[str, tuple[np.dtype, int]] = {
    "rgb8": (np.dtype(np.uint8), 3),
    "bgr8": (np.dtype(np.uint8), 3),
    "rgba8": (np.dtype(np.uint8), 4),
    "bgra8": (np.dtype(np.uint8), 4),
    "mono8": (np.dtype(np.uint8), 1),
    "8UC1": (np.dtype(np.uint8), 1),
    "8UC3": (np.dtype(np.uint8), 3),
    "mono16": (np.dtype(np.uint16), 1),
    "16UC1": (np.dtype(np.uint16), 1),
    "32FC1": (np.dtype(np.float32), 1),
}


def image_to_array(message: Image) -> np.ndarray:
    """Return the pixels of an Image as an (H, W) or (H, W, C) array, in the message's encoding.

    Row padding (step larger than width * pixel size) and big-endian data are handled; the
    returned array never aliases the message's buffer.
    """
    encoding = message.encoding
    if encoding not in IMAGE_ENCODINGS:
        supported = ", ".join(IMAGE_ENCODINGS)
        raise InvalidInputError(f"image encoding '{encoding}' is not supported (supported: {supported})")
    dtype, channels = IMAGE_ENCODINGS[encoding]
    height, width, step = int(message.height), int(message.width), int(message.step)
    if height <= 0 or width <= 0:
        raise InvalidInputError(f"image has no pixels ({width}x{height})")
    row_bytes = width * channels * dtype.itemsize
    if step < row_bytes:
        raise InvalidInputError(f"image step {step} is smaller than a row of {row_bytes} bytes")
    data = message.data
    buffer = data.tobytes() if hasattr(data, "tobytes") else bytes(data)
    if len(buffer) < step * height:
        raise InvalidInputError(
            f"image data holds {len(buffer)} bytes, {step * height} expected for {width}x{height} "
            f"'{encoding}' with step {step}"
        )
    rows = np.frombuffer(buffer, dtype=np.uint8, count=step * height).reshape(height, step)
    pixel_dtype = dtype.newbyteorder(">") if message.is_bigendian else dtype
    pixels = rows[:, :row_bytes].copy().view(pixel_dtype).astype(dtype, copy=False)
    return pixels.reshape(height, width) if channels == 1 else pixels.reshape(height, width, channels)


def array_to_image(array: np.ndarray, encoding: str, header: Header | None = None) -> Image:
    """Build an Image from an array; the array's dtype and shape must fit the encoding."""
    if encoding not in IMAGE_ENCODINGS:
        raise InvalidInputError(f"image encoding '{encoding}' is not supported")
    dtype, channels = IMAGE_ENCODINGS[encoding]
    expected_dimensions = 2 if channels == 1 else 3
    if array.ndim != expected_dimensions or (channels > 1 and array.shape[2] != channels):
        raise InvalidInputError(f"array of shape {array.shape} does not fit encoding '{encoding}'")
    if array.dtype != dtype:
        raise InvalidInputError(f"array of dtype {array.dtype} does not fit encoding '{encoding}' ({dtype})")
    contiguous = np.ascontiguousarray(array)
    message = Image()
    if header is not None:
        message.header = header
    message.height, message.width = int(contiguous.shape[0]), int(contiguous.shape[1])
    message.encoding = encoding
    message.is_bigendian = 0
    message.step = int(contiguous.shape[1] * channels * dtype.itemsize)
    message.data = contiguous.tobytes()
    return message


def stamp_to_seconds(stamp: Time) -> float:
    return float(stamp.sec) + float(stamp.nanosec) * 1e-9


def seconds_to_stamp(seconds: float) -> Time:
    whole = int(np.floor(seconds))
    nanoseconds = int(round((seconds - whole) * 1e9))
    if nanoseconds >= 1_000_000_000:
        whole, nanoseconds = whole + 1, nanoseconds - 1_000_000_000
    return Time(sec=whole, nanosec=nanoseconds)


def camera_info_message(
    width: int, height: int, fx: float, fy: float, cx: float, cy: float, header: Header | None = None
) -> CameraInfo:
    """A CameraInfo for an undistorted pinhole camera with the given intrinsics."""
    message = CameraInfo()
    if header is not None:
        message.header = header
    message.width, message.height = int(width), int(height)
    message.distortion_model = "plumb_bob"
    message.d = [0.0] * 5
    message.k = [fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0]
    message.r = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    message.p = [fx, 0.0, cx, 0.0, 0.0, fy, cy, 0.0, 0.0, 0.0, 1.0, 0.0]
    return message
