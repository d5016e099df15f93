"""Approximate-time synchronisation: matching, slop, bounded queues, late messages, determinism."""

from __future__ import annotations

import pytest

from merlin2_sailor.errors import ConfigurationError, InvalidInputError
from merlin2_sailor.perception.synchroniser import ApproximateTimeSynchroniser, SynchroniserConfig


def synchroniser(
    slop: float = 0.02, queue_size: int = 5, inputs: tuple[str, ...] = ("rgb", "depth")
) -> ApproximateTimeSynchroniser:
    return ApproximateTimeSynchroniser(inputs, SynchroniserConfig(slop=slop, queue_size=queue_size))


def test_identical_stamps_match_immediately() -> None:
    sync = synchroniser()
    assert sync.push("rgb", 1.0, "rgb1") is None
    matched = sync.push("depth", 1.0, "depth1")
    assert matched is not None and matched.messages == {"rgb": "rgb1", "depth": "depth1"} and matched.stamp == 1.0


def test_nearby_stamps_match_within_the_slop_only() -> None:
    sync = synchroniser(slop=0.02)
    sync.push("rgb", 1.000, "rgb1")
    assert sync.push("depth", 1.030, "far") is None  # 30 ms apart: too far
    sync.push("rgb", 1.040, "rgb2")  # pairs with the 1.030 depth: 10 ms
    # ...which already happened on that push; the next depth near 1.000 is now late
    assert sync.push("depth", 0.999, "late") is None


def test_the_nearest_partner_is_chosen() -> None:
    sync = synchroniser(slop=0.05)
    sync.push("depth", 0.97, "d97")
    sync.push("depth", 0.99, "d99")
    matched = sync.push("rgb", 1.00, "r100")
    assert matched is not None and matched.messages["depth"] == "d99"
    # d97 is older than the emitted set and was discarded with it.
    assert sync.push("rgb", 1.10, "r110") is None


def test_queues_are_bounded_and_drop_the_oldest() -> None:
    sync = synchroniser(slop=0.001, queue_size=3)
    for index in range(5):
        sync.push("rgb", float(index), f"rgb{index}")
    # Only stamps 2, 3, 4 remain: depth at 0 or 1 finds no partner, depth at 3 does.
    assert sync.push("depth", 0.0, "d0") is None
    assert sync.push("depth", 1.0, "d1") is None
    matched = sync.push("depth", 3.0, "d3")
    assert matched is not None and matched.messages["rgb"] == "rgb3"


def test_out_of_order_arrivals_are_sorted() -> None:
    sync = synchroniser(slop=0.001)
    sync.push("rgb", 2.0, "rgb2")
    sync.push("rgb", 1.0, "rgb1")
    matched = sync.push("depth", 1.0, "d1")
    assert matched is not None and matched.messages["rgb"] == "rgb1"
    matched = sync.push("depth", 2.0, "d2")
    assert matched is not None and matched.messages["rgb"] == "rgb2"


def test_three_inputs_need_all_three() -> None:
    sync = synchroniser(slop=0.01, inputs=("rgb", "depth", "info"))
    assert sync.push("rgb", 5.0, "r") is None
    assert sync.push("depth", 5.004, "d") is None
    matched = sync.push("info", 5.008, "i")
    assert matched is not None and set(matched.messages) == {"rgb", "depth", "info"} and matched.stamp == 5.008


def test_same_input_sequence_gives_the_same_output() -> None:
    def run() -> list[tuple[float, dict[str, int]]]:
        sync = synchroniser(slop=0.015, queue_size=4)
        emitted = []
        for step in range(200):
            stamp = step * 0.033
            emitted.append(sync.push("rgb", stamp + 0.001 * (step % 7), step))
            if step % 5:  # the depth stream loses every fifth frame
                emitted.append(sync.push("depth", stamp + 0.002 * (step % 3), step))
        return [(m.stamp, m.messages) for m in emitted if m is not None]

    first = run()
    assert first == run()
    assert len(first) == 160  # every frame that has both streams, and no other
    assert all(messages["rgb"] == messages["depth"] for _, messages in first)


def test_invalid_use_is_rejected() -> None:
    with pytest.raises(ConfigurationError):
        ApproximateTimeSynchroniser(["only"])
    with pytest.raises(ConfigurationError):
        ApproximateTimeSynchroniser(["a", "a"])
    with pytest.raises(ConfigurationError):
        SynchroniserConfig(slop=-1.0)
    with pytest.raises(ConfigurationError):
        SynchroniserConfig(queue_size=0)
    sync = synchroniser()
    with pytest.raises(InvalidInputError):
        sync.push("lidar", 1.0, None)
    with pytest.raises(InvalidInputError):
        sync.push("rgb", float("nan"), None)
