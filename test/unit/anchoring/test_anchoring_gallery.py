"""Gallery storage: bfloat16 rounding, exact special values, the last K kept."""

from __future__ import annotations

import numpy as np
import pytest

from merlin2_sailor.anchoring.gallery import add_to_gallery, from_bfloat16_bits, to_bfloat16_bits
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
