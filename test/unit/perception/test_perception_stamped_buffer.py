from __future__ import annotations

import pytest

from merlin2_sailor.perception.stamped_buffer import StampedBuffer


def test_nearest_within_tolerance_and_bounded() -> None:
    buffer: StampedBuffer[str] = StampedBuffer(capacity=3, tolerance=0.05)
    for stamp in (1.0, 1.1, 1.2, 1.3):
        buffer.add(stamp, f"pose@{stamp}")
    assert buffer.nearest(1.21) == "pose@1.2"
    assert buffer.nearest(1.0) is None  # pushed out by the capacity
    assert buffer.nearest(1.5) is None  # too far from anything
    assert buffer.latest() == "pose@1.3"
    with pytest.raises(ValueError):
        StampedBuffer(capacity=0)
