"""Gallery storage: bfloat16 rounding, exact special values; which K views are kept."""

from __future__ import annotations

import numpy as np
import pytest

from merlin2_sailor.anchoring.gallery import add_to_gallery, add_view, from_bfloat16_bits, to_bfloat16_bits
from merlin2_sailor.errors import InvalidInputError


def test_round_trip_is_within_bfloat16_precision():
    values = np.random.default_rng(0).normal(scale=3.0, size=10_000).astype(np.float32)
    restored = from_bfloat16_bits(to_bfloat16_bits(values))
    assert restored.dtype == np.float32
    np.testing.assert_allclose(restored, values, rtol=2**-8)
    # rounding to nearest: the error is half what truncation would give, on average
    assert np.mean(np.abs(restored - values) / np.abs(values)) < 2**-9


def test_exact_values_survive():
    exact = np.array([0.0, -0.0, 1.0, -2.5, 0.15625, 1e30, -1e-30], dtype=np.float32)
    restored = from_bfloat16_bits(to_bfloat16_bits(exact))
    np.testing.assert_array_equal(restored[:5], exact[:5])
    np.testing.assert_allclose(restored[5:], exact[5:], rtol=2**-8)  # float32's range is kept


def test_ties_round_to_even():
    # 1 + 2^-8 lies halfway between two bfloat16 numbers: 1 (even) and 1 + 2^-7
    halfway = np.array([1.0 + 2**-8, 1.0 + 3 * 2**-8], dtype=np.float32)
    np.testing.assert_array_equal(from_bfloat16_bits(to_bfloat16_bits(halfway)), [1.0, 1.0 + 2**-6])


@pytest.mark.parametrize("size", [1, 2, 4])
def test_the_last_size_embeddings_are_kept(size):
    gallery = None
    for number in range(6):
        gallery = add_to_gallery(gallery, np.full(3, float(number), np.float32), size)
        assert len(gallery) == min(number + 1, size)
    np.testing.assert_array_equal(from_bfloat16_bits(gallery)[:, 0], np.arange(6 - size, 6, dtype=np.float32))


def test_a_different_dimension_is_refused():
    gallery = add_to_gallery(None, np.zeros(4, np.float32), 3)
    with pytest.raises(InvalidInputError, match="backbone changed"):
        add_to_gallery(gallery, np.zeros(5, np.float32), 3)


def _gallery_of(sizes, gallery_size):
    """Views numbered 0, 1, ... (the number is the embedding) of the given box sizes, in order."""
    gallery = scales = None
    for number, size in enumerate(sizes):
        gallery, scales = add_view(gallery, scales, np.full(3, float(number), np.float32), size, gallery_size)
    return from_bfloat16_bits(gallery)[:, 0].astype(int).tolist(), scales.tolist()


@pytest.mark.parametrize(("close", "departing"), [
    ([50.0, 52.0, 48.0, 49.0], [40.0, 35.0, 30.0, 25.0, 20.0]),
    ([80.0, 75.0, 90.0, 85.0], [60.0, 45.0, 33.0]),
    ([30.0, 31.0, 29.0, 30.5], [24.0, 20.0, 17.0, 15.0, 13.0, 12.0]),
])
def test_an_object_left_behind_keeps_its_close_views(close, departing):
    views, scales = _gallery_of([*close, *departing], 4)
    assert views[-1] == len(close) + len(departing) - 1  # the newest view is kept, last
    assert scales[-1] == departing[-1]
    assert sorted(scales[:-1]) == sorted(close)[1:]  # only the close view nearest the far ones gave way


@pytest.mark.parametrize("size", [1, 2, 4])
def test_views_of_one_size_are_refreshed_oldest_first(size):
    views, _ = _gallery_of([40.0] * 7, size)
    assert views == list(range(7 - size, 7))


def test_an_approach_refreshes_one_view_and_keeps_the_far_ones():
    views, scales = _gallery_of([20.0, 25.0, 30.0, 40.0, 50.0, 55.0, 60.0], 4)
    assert views == [0, 1, 2, 6]
    assert scales == [20.0, 25.0, 30.0, 60.0]


@pytest.mark.parametrize("unknown", [float("nan"), 0.0])
def test_where_a_size_is_unknown_the_oldest_view_goes(unknown):
    views, _ = _gallery_of([50.0, 52.0, unknown, 49.0, 20.0, 21.0], 4)
    assert views == [2, 3, 4, 5]
    gallery, scales = add_view(None, None, np.zeros(3, np.float32), 40.0, 2)
    gallery, scales = add_view(gallery, None, np.ones(3, np.float32), 40.0, 2)  # the sizes were lost
    gallery, scales = add_view(gallery, scales, np.full(3, 2.0, np.float32), 41.0, 2)
    assert from_bfloat16_bits(gallery)[:, 0].tolist() == [1.0, 2.0]


def test_add_view_refuses_another_dimension():
    gallery, scales = add_view(None, None, np.zeros(4, np.float32), 30.0, 1)
    with pytest.raises(InvalidInputError, match="backbone changed"):
        add_view(gallery, scales, np.zeros(5, np.float32), 30.0, 1)
