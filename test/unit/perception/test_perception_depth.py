"""Depth decoding: units, missing-value conventions and raw buffers."""

from __future__ import annotations

import numpy as np
import pytest

from merlin2_sailor.errors import InvalidInputError
from merlin2_sailor.perception.depth import decode_depth_buffer, depth_to_metres


@pytest.mark.parametrize("encoding", ["16UC1", "mono16"])
def test_millimetre_images_become_metres_and_zero_becomes_nan(encoding: str) -> None:
    depth = depth_to_metres(np.array([[1500, 0], [65535, 1]], dtype=np.uint16), encoding)
    assert depth.dtype == np.float32
    np.testing.assert_allclose(depth, [[1.5, np.nan], [65.535, 0.001]], rtol=1e-6)


def test_float_metres_keep_values_and_lose_invalid_readings() -> None:
    raw = np.array([[2.25, np.nan, np.inf], [-np.inf, -1.0, 0.0]], dtype=np.float32)
    depth = depth_to_metres(raw, "32FC1")
    assert depth[0, 0] == pytest.approx(2.25)
    assert np.isnan(depth.reshape(-1)[1:]).all()


def test_single_channel_third_axis_is_accepted() -> None:
    assert depth_to_metres(np.ones((4, 5, 1), dtype=np.float32), "32FC1").shape == (4, 5)


@pytest.mark.parametrize("encoding", ["rgb8", "16SC1", "", "32fc1"])
def test_unknown_encodings_are_rejected(encoding: str) -> None:
    with pytest.raises(InvalidInputError, match="encoding"):
        depth_to_metres(np.ones((2, 2), dtype=np.uint16), encoding)


def test_buffer_with_row_padding_and_big_endian() -> None:
    values = np.array([[1000, 2000, 3000], [4000, 5000, 6000]], dtype=">u2")
    padded = np.zeros((2, 8), dtype=np.uint8)  # 6 bytes of pixels + 2 bytes of padding per row
    padded[:, :6] = values.view(np.uint8).reshape(2, 6)
    depth = decode_depth_buffer(padded.tobytes(), "16UC1", height=2, width=3, step=8, is_bigendian=True)
    np.testing.assert_allclose(depth, values.astype(np.float32) / 1000.0)


def test_float_buffer_round_trip() -> None:
    values = np.array([[0.5, 1.5], [2.5, 3.5]], dtype="<f4")
    np.testing.assert_allclose(decode_depth_buffer(values.tobytes(), "32FC1", 2, 2), values)


@pytest.mark.parametrize(
    "arguments",
    [
        dict(data=b"\x00" * 10, encoding="16UC1", height=2, width=3),  # needs 12 bytes
        dict(data=b"\x00" * 12, encoding="16UC1", height=2, width=3, step=4),  # step shorter than a row
        dict(data=b"\x00" * 12, encoding="bgr8", height=2, width=3),
        dict(data=b"", encoding="32FC1", height=0, width=3),
    ],
)
def test_bad_buffers_are_rejected(arguments: dict) -> None:
    with pytest.raises(InvalidInputError):
        decode_depth_buffer(**arguments)
