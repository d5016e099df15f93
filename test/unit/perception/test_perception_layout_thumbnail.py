"""The layout thumbnail that ends each crop descriptor: what it tells apart that histograms cannot."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from merlin2_sailor.errors import InvalidInputError
from merlin2_sailor.perception.colour_histogram import COLOUR_DESCRIPTOR_SIZE, colour_descriptor, colour_similarity
from merlin2_sailor.perception.crop_descriptor import (
    DESCRIPTOR_SIMILARITIES,
    DESCRIPTOR_SIZE,
    crop_descriptor,
    crop_descriptors,
    descriptor_similarity,
)
from merlin2_sailor.perception.layout_thumbnail import GRID, LAYOUT_SIZE, layout_descriptor, layout_similarity


def picture(seed: int, size: tuple[int, int] = (90, 120)) -> np.ndarray:
    """An asymmetric picture: coloured blobs and a bar at random places on a light ground."""
    rng = np.random.default_rng(seed)
    height, width = size
    image = np.full((height, width, 3), 225, dtype=np.uint8)
    for _ in range(4):
        centre = (int(rng.integers(0, width)), int(rng.integers(0, height)))
        colour = tuple(int(c) for c in rng.integers(0, 200, 3))
        cv2.circle(image, centre, int(rng.integers(height // 8, height // 3)), colour, thickness=-1)
    left = int(rng.integers(0, width // 2))
    cv2.rectangle(image, (left, height // 5), (left + width // 6, height - height // 5), (20, 20, 90), thickness=-1)
    return image


def another_view(image: np.ndarray, scale: float, shift: tuple[int, int], gain: float, seed: int) -> np.ndarray:
    """The same picture seen again: a box a little off, nearer or farther, other light, sensor noise."""
    height, width = image.shape[:2]
    matrix = np.array([[scale, 0.0, shift[0]], [0.0, scale, shift[1]]])
    moved = cv2.warpAffine(image, matrix, (width, height), borderMode=cv2.BORDER_REFLECT).astype(np.float32)
    noisy = moved * gain + np.random.default_rng(seed).normal(0.0, 4.0, moved.shape)
    size = (int(width * scale * 0.8), int(height * scale * 0.8))
    return cv2.resize(np.clip(noisy, 0, 255).astype(np.uint8), size, interpolation=cv2.INTER_AREA)


def layout(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    return layout_similarity(np.abs(layout_descriptor(first) - layout_descriptor(second)))


def test_a_mirror_image_has_the_same_colours_but_not_the_same_layout() -> None:
    told_apart = 0
    for seed in range(8):
        image = picture(seed)
        mirror = np.ascontiguousarray(image[:, ::-1])
        # Histograms cannot tell them apart...
        colours = colour_similarity(np.abs(colour_descriptor(image) - colour_descriptor(mirror)))
        assert colours.min() > 0.97
        # ...the layout can: less alike than two views of the picture itself, and by far unless the
        # picture happens to be nearly symmetric.
        mirrored = layout(image, mirror)
        own = layout(image, another_view(image, 1.05, (3, -2), 1.15, seed))
        assert own[0] > 0.7 and own[1] > 0.7
        assert mirrored.sum() < own.sum() - 0.15
        told_apart += bool(mirrored[0] < own[0] - 0.3)
    assert told_apart >= 6


@pytest.mark.parametrize("seed", range(6))
def test_another_cut_of_one_photo_or_another_border_differs_in_layout(seed: int) -> None:
    photo = picture(seed, (180, 240))
    cut = photo[20:110, 30:150]
    other_cut = photo[70:160, 110:230]
    framed = cv2.copyMakeBorder(cut[24:-24, 24:-24], 24, 24, 24, 24, cv2.BORDER_CONSTANT, value=(200, 20, 20))
    own_correlation, own_closeness = layout(cut, another_view(cut, 0.95, (-2, 3), 0.9, seed))
    other_correlation, other_closeness = layout(cut, other_cut)
    _, framed_closeness = layout(cut, framed)
    assert other_correlation < own_correlation - 0.3
    assert framed_closeness < own_closeness - 0.1


def test_the_correlation_read_from_a_difference_is_the_lightness_patterns_correlation() -> None:
    first, second = picture(1), picture(2)
    first_layout, second_layout = layout_descriptor(first), layout_descriptor(second)
    lightness = GRID * GRID
    expected = np.corrcoef(first_layout[:lightness], second_layout[:lightness])[0, 1]
    correlation, closeness = layout_similarity(np.abs(first_layout - second_layout))
    assert correlation == pytest.approx(expected, abs=1e-5)
    # Cells' colours are CIELAB / 100: the closeness is 1 - the mean cell distance / 100.
    cells = np.abs(first_layout[lightness:] - second_layout[lightness:]).reshape(-1, 3) * 100.0
    assert closeness == pytest.approx(1.0 - np.linalg.norm(cells, axis=1).mean() / 100.0, abs=1e-5)


def test_flat_tiny_and_bad_crops() -> None:
    flat = np.full((30, 40, 3), 120, dtype=np.uint8)
    descriptor = layout_descriptor(flat)
    assert descriptor.shape == (LAYOUT_SIZE,) and descriptor.dtype == np.float32
    assert np.all(descriptor[: GRID * GRID] == 0.0) and np.all(np.isfinite(descriptor))
    assert layout(flat, flat) == pytest.approx([1.0, 1.0])
    tiny = layout_descriptor(picture(3, (5, 4)))  # smaller than the grid: no margin is cut
    assert tiny.shape == (LAYOUT_SIZE,) and np.all(np.isfinite(tiny))
    for bad in (np.zeros((0, 4, 3), np.uint8), np.zeros((4, 4), np.uint8), np.zeros((4, 4, 3), np.float32)):
        with pytest.raises(InvalidInputError):
            layout_descriptor(bad)


def test_a_crop_descriptor_is_the_colour_descriptor_then_the_layout() -> None:
    crops = [picture(4), picture(5, (40, 30))]
    descriptors = crop_descriptors(crops)
    assert descriptors.shape == (2, DESCRIPTOR_SIZE) == (2, COLOUR_DESCRIPTOR_SIZE + LAYOUT_SIZE)
    np.testing.assert_array_equal(descriptors[0], crop_descriptor(crops[0]))
    np.testing.assert_array_equal(descriptors[0, :COLOUR_DESCRIPTOR_SIZE], colour_descriptor(crops[0]))
    np.testing.assert_array_equal(descriptors[0, COLOUR_DESCRIPTOR_SIZE:], layout_descriptor(crops[0]))
    assert crop_descriptors([]).shape == (0, DESCRIPTOR_SIZE)
    similarities = descriptor_similarity(np.abs(descriptors[0] - descriptors[1])[np.newaxis])
    assert similarities.shape == (1, DESCRIPTOR_SIMILARITIES)
    assert np.all(descriptor_similarity(np.zeros((3, DESCRIPTOR_SIZE))) == 1.0)  # a crop is like itself
