"""Depth images in metres, whatever encoding the driver published.

RGB-D drivers disagree on units: OpenNI-style drivers publish ``16UC1`` millimetres, others
``32FC1`` metres, and each marks "no measurement" differently (0, NaN or +/-inf). Everything
downstream wants one thing: float32 metres with NaN where there is no usable depth, so the
geometry code needs a single validity test. REP 118 defines both encodings.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

import numpy as np

from merlin2_sailor.errors import InvalidInputError

#: Metres per stored unit for each supported encoding; ``mono16`` is what some drivers call
#: their millimetre image, and it is read the same way as ``16UC1``.
_METRES_PER_UNIT = MappingProxyType({"16UC1": 0.001, "mono16": 0.001, "32FC1": 1.0})
_STORED_DTYPE: Mapping[str, np.dtype] = MappingProxyType(
    {"16UC1": np.dtype(np.uint16), "mono16": np.dtype(np.uint16), "32FC1": np.dtype(np.float32)}
)

SUPPORTED_DEPTH_ENCODINGS = tuple(_METRES_PER_UNIT)


def depth_to_metres(depth: np.ndarray, encoding: str) -> np.ndarray:
    """Return a float32 copy of an (H, W) depth image in metres, NaN where there is no depth.

    Zero, negative and non-finite values all mean "no measurement" and become NaN.
    """
    if encoding not in _METRES_PER_UNIT:
        raise InvalidInputError(
            f"Unsupported depth encoding {encoding!r}; expected one of {', '.join(SUPPORTED_DEPTH_ENCODINGS)} "
            "(REP 118). Configure the camera driver to publish one of these."
        )
    depth = np.asarray(depth)
    if depth.ndim == 3 and depth.shape[2] == 1:
        depth = depth[:, :, 0]
    if depth.ndim != 2:
        raise InvalidInputError(f"A depth image must be 2-D (H, W), got shape {depth.shape}.")
    metres = depth.astype(np.float32) * np.float32(_METRES_PER_UNIT[encoding])
    with np.errstate(invalid="ignore"):
        metres[~(metres > 0.0) | ~np.isfinite(metres)] = np.nan
    return metres


def decode_depth_buffer(
    data: bytes | bytearray | memoryview,
    encoding: str,
    height: int,
    width: int,
    step: int | None = None,
    is_bigendian: bool = False,
) -> np.ndarray:
    """Decode a raw depth buffer (the fields of a ``sensor_msgs/Image``) into metres.

    ``step`` is the row length in bytes, which drivers may pad beyond ``width * bytes_per_pixel``;
    the padding is skipped rather than read as pixels.
    """
    if encoding not in _STORED_DTYPE:
        raise InvalidInputError(
            f"Unsupported depth encoding {encoding!r}; expected one of {', '.join(SUPPORTED_DEPTH_ENCODINGS)}."
        )
    if height <= 0 or width <= 0:
        raise InvalidInputError(f"A depth image must have a positive size, got {width}x{height}.")
    dtype = _STORED_DTYPE[encoding].newbyteorder(">" if is_bigendian else "<")
    row_bytes = width * dtype.itemsize
    step = row_bytes if step is None else step
    if step < row_bytes:
        raise InvalidInputError(f"Row step {step} bytes is shorter than one row of {width} pixels ({row_bytes} bytes).")
    buffer = np.frombuffer(data, dtype=np.uint8)
    if buffer.size < step * height:
        raise InvalidInputError(
            f"Depth buffer holds {buffer.size} bytes but {height} rows of {step} bytes need {step * height}."
        )
    rows = buffer[: step * height].reshape(height, step)[:, :row_bytes]
    stored = np.ascontiguousarray(rows).view(dtype).reshape(height, width)
    return depth_to_metres(stored, encoding)
