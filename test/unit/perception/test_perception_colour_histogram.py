"""The colour descriptor that ends each crop embedding: what it separates and what it keeps alike."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from merlin2_sailor.errors import InvalidInputError
from merlin2_sailor.perception.colour_histogram import (
    COLOUR_BINS,
    COLOUR_DESCRIPTOR_SIZE,
    GREY_BINS,
    HUE_BINS,
    MINIMUM_OBJECT_PIXELS,
    colour_descriptor,
    colour_histogram,
    colour_similarity,
    object_colour,
    object_colour_similarity,
)
from merlin2_sailor.perception.crop_descriptor import DESCRIPTOR_SIZE, crop_descriptors


def plain(rgb: tuple[int, int, int], size: tuple[int, int] = (20, 30)) -> np.ndarray:
    return np.full((*size, 3), rgb, dtype=np.uint8)


def mug(rim: tuple[int, int, int], size: int, centre_shift: int = 0, rim_width: float = 0.12) -> np.ndarray:
    """A top view of a mug: a coffee-coloured disc inside a rim of ``rim``'s colour, on a wooden table."""
    image = np.full((size, size, 3), (150, 100, 60), dtype=np.uint8)
    centre = (size // 2 + centre_shift, size // 2)
    radius = int(size * 0.45)
    cv2.circle(image, centre, radius, rim, thickness=-1)
    cv2.circle(image, centre, int(radius * (1.0 - 2.0 * rim_width)), (200, 120, 40), thickness=-1)
    return image


def similarity(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    return colour_similarity(np.abs(colour_descriptor(first) - colour_descriptor(second)))


def test_a_descriptor_is_two_histograms_that_each_sum_to_one():
    descriptor = colour_descriptor(mug((220, 30, 30), 50))
    assert descriptor.shape == (COLOUR_DESCRIPTOR_SIZE,) == (2 * COLOUR_BINS,) and descriptor.dtype == np.float32
    assert descriptor[:COLOUR_BINS].sum() == pytest.approx(1.0) and descriptor[COLOUR_BINS:].sum() == pytest.approx(1.0)
    assert descriptor.min() >= 0.0


def test_primary_colours_fill_different_hue_bins_and_greys_the_grey_bins():
    red, green, blue = (colour_histogram(plain(c)) for c in ((255, 0, 0), (0, 255, 0), (0, 0, 255)))
    supports = [set(np.flatnonzero(h).tolist()) for h in (red, green, blue)]
    assert all(support and max(support) < HUE_BINS for support in supports)
    assert not (supports[0] & supports[1] or supports[1] & supports[2] or supports[0] & supports[2])
    dark, mid, light = (colour_histogram(plain((v, v, v))) for v in (10, 128, 250))
    assert [int(np.argmax(h)) for h in (dark, mid, light)] == [HUE_BINS + i for i in range(GREY_BINS)]
    assert similarity(plain((255, 0, 0)), plain((0, 255, 0))).tolist() == [0.0, 0.0]
    assert similarity(plain((10, 10, 10)), plain((250, 250, 250))).tolist() == [0.0, 0.0]


def test_a_hue_near_a_bins_edge_is_shared_so_a_small_change_of_hue_changes_little():
    hsv = np.zeros((10, 10, 3), dtype=np.uint8)
    hsv[..., 1:] = 255
    histograms = []
    for hue in range(0, 256, 3):  # OpenCV's full hue range: 0..255 for 0..360 degrees
        hsv[..., 0] = hue
        histograms.append(colour_histogram(cv2.cvtColor(hsv, cv2.COLOR_HSV2RGB_FULL)))
    steps = [np.abs(a - b).sum() for a, b in zip(histograms, histograms[1:], strict=False)]
    assert max(steps) < 0.6  # a hard binning would jump by 2 at every edge


def test_the_surround_tells_mugs_of_one_make_apart_by_their_rims_and_the_centre_does_not():
    # Seen from another distance and off-centre, the same red mug; mugs of one make with other rims.
    red_near, red_far = mug((220, 30, 30), 80), mug((220, 30, 30), 36, centre_shift=3, rim_width=0.09)
    centre_same, surround_same = similarity(red_near, red_far)
    for other in ((40, 80, 220), (40, 180, 60), (240, 240, 240)):
        centre, surround = similarity(red_near, mug(other, 36))
        assert surround_same > surround + 0.2, other
        assert centre > 0.6  # the coffee in the middle is shared: a whole-crop histogram is swamped by it
    assert centre_same > 0.8 and surround_same > 0.7


def test_a_large_crop_is_shrunk_first_without_changing_its_colours():
    small, large = mug((40, 180, 60), 48), mug((40, 180, 60), 480)
    assert np.all(similarity(small, large) > 0.9)  # edges blend a little when shrunk


def test_a_sliver_too_thin_for_a_surround_uses_the_whole_crop_for_both():
    sliver = plain((0, 0, 255), (1, 30))
    descriptor = colour_descriptor(sliver)
    np.testing.assert_array_equal(descriptor[:COLOUR_BINS], descriptor[COLOUR_BINS:])
    np.testing.assert_array_equal(descriptor[:COLOUR_BINS], colour_histogram(sliver))


def test_a_batch_is_one_descriptor_per_crop_and_bad_crops_are_refused():
    crops = [mug((220, 30, 30), 40), plain((0, 0, 255), (1, 1))]
    batch = crop_descriptors(crops)  # a batch of crop descriptors starts with the colour descriptors
    assert batch.shape == (2, DESCRIPTOR_SIZE) and DESCRIPTOR_SIZE > COLOUR_DESCRIPTOR_SIZE
    np.testing.assert_array_equal(batch[1, :COLOUR_DESCRIPTOR_SIZE], colour_descriptor(crops[1]))
    assert crop_descriptors([]).shape == (0, DESCRIPTOR_SIZE)
    for bad in (np.zeros((0, 4, 3), np.uint8), np.zeros((4, 4), np.uint8), np.zeros((4, 4, 3), np.float32)):
        with pytest.raises(InvalidInputError, match="colour descriptor"):
            colour_descriptor(bad)
    with pytest.raises(InvalidInputError, match="colour histogram"):
        colour_histogram(np.zeros((0, 3), np.uint8))


def test_an_object_colour_reads_only_the_marked_pixels_and_needs_enough_of_them():
    crop = plain((220, 20, 20), (60, 60))
    crop[10:40, 10:40] = (20, 200, 40)
    pixels = np.zeros((60, 60), dtype=bool)
    pixels[10:40, 10:40] = True
    colour = object_colour(crop, pixels)
    np.testing.assert_allclose(colour, colour_histogram(plain((20, 200, 40))), atol=1e-6)
    assert object_colour_similarity(colour, colour_histogram(crop)) == pytest.approx(0.25, abs=0.01)
    # A far object's few pixels are mostly its outline: too few to tell its colour.
    few = np.zeros((60, 60), dtype=bool)
    few[10:20, 10:20] = True
    assert few.sum() < MINIMUM_OBJECT_PIXELS and object_colour(crop, few) is None
    with pytest.raises(InvalidInputError, match="do not match"):
        object_colour(crop, pixels[:20])


def test_an_object_colour_of_many_pixels_is_an_even_subsample_of_them():
    rng = np.random.default_rng(0)
    crop = rng.integers(0, 256, size=(300, 400, 3), dtype=np.uint8)
    everything = np.ones((300, 400), dtype=bool)
    subsampled = object_colour(crop, everything)
    np.testing.assert_allclose(subsampled, colour_histogram(crop), atol=0.02)
