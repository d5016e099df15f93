"""A crop's layout as a tiny thumbnail: where its colours are, which pooled features and histograms lose.

Average-pooled backbone features and colour histograms both forget *where* things are in a crop.
So neither tells an object from a relative made of the same picture mirrored, cut at another
place or framed by another border: on the held-out generated houses, most of the matching
network's false pairs between look-alikes were such relatives a row apart, with backbone cosines
of 0.7-0.9 and histograms as close as two views of one object. A 6 x 6 thumbnail of the crop's
middle keeps the layout. Measured on four held-out houses (same class, under 1 m apart, whole
views): the mean per-cell colour distance (CIELAB) between two views of one object has a median
of 8 (95th percentile 31), between different objects 33, and 36 over the network's false pairs;
the correlation of the thumbnails' lightness is 0.79 (median) for one object's views, 0.11 for
different ones.

Layout of a descriptor (:data:`LAYOUT_SIZE` values): the lightness of the :data:`GRID` x
:data:`GRID` cells, less its mean and divided by its norm (so the correlation of two crops is
``1 - |a - b|^2 / 2``, readable from their difference as the matching network reads everything),
then the cells' CIELAB colours divided by 100 (so a cell's colour distance is 100 times the norm
of its three differences). Both are read back from the element-wise absolute difference of two
descriptors by :func:`layout_similarity`.
"""

from __future__ import annotations

import cv2
import numpy as np

from merlin2_sailor.perception.rgb_crop import checked_rgb_crop

#: Cells of the thumbnail per side.
GRID = 6
#: The thumbnail leaves this fraction of the crop's width (height) out on each side: the box's
#: edges hold the background more than the object.
LAYOUT_MARGIN = 0.15
#: Values of the lightness pattern, then of the cells' colours.
LIGHTNESS_VALUES = GRID * GRID
COLOUR_CELL_VALUES = 3 * GRID * GRID
#: Values per layout descriptor.
LAYOUT_SIZE = LIGHTNESS_VALUES + COLOUR_CELL_VALUES
#: Similarities :func:`layout_similarity` reads from a pair: lightness correlation, colour closeness.
LAYOUT_SIMILARITIES = 2
#: A cell colour distance (CIELAB) at which the colour closeness reaches 0.
COLOUR_DISTANCE_SCALE = 100.0
#: A lightness pattern with a norm below this is flat (a plain surface): it is left all zeros.
_FLAT = 1e-3


def layout_descriptor(crop: np.ndarray) -> np.ndarray:
    """(LAYOUT_SIZE,) float32 layout of one (H, W, 3) uint8 RGB crop (see the module docstring)."""
    crop = checked_rgb_crop(crop, "A layout descriptor")
    height, width = crop.shape[:2]
    top, left = int(height * LAYOUT_MARGIN), int(width * LAYOUT_MARGIN)
    if height - 2 * top >= GRID and width - 2 * left >= GRID:
        crop = crop[top : height - top, left : width - left]
    thumbnail = cv2.resize(np.ascontiguousarray(crop), (GRID, GRID), interpolation=cv2.INTER_AREA)
    lab = cv2.cvtColor(thumbnail.astype(np.float32) / 255.0, cv2.COLOR_RGB2LAB).reshape(-1, 3)
    lightness = lab[:, 0] - lab[:, 0].mean()
    norm = float(np.linalg.norm(lightness))
    lightness = lightness / norm if norm > _FLAT else np.zeros_like(lightness)
    return np.concatenate([lightness, lab.ravel() / 100.0]).astype(np.float32)


def layout_similarity(descriptor_difference: np.ndarray) -> np.ndarray:
    """(..., LAYOUT_SIMILARITIES) from the (..., LAYOUT_SIZE) absolute difference of two layout
    descriptors: the correlation of their lightness patterns (1: the same pattern, -1: inverted)
    and the closeness of their cells' colours (1: the same, 0: a mean cell distance of
    :data:`COLOUR_DISTANCE_SCALE` or more)."""
    difference = np.asarray(descriptor_difference, dtype=np.float64)
    lightness = difference[..., :LIGHTNESS_VALUES]
    cells = difference[..., LIGHTNESS_VALUES:].reshape(*difference.shape[:-1], GRID * GRID, 3)
    correlation = np.clip(1.0 - 0.5 * np.square(lightness).sum(axis=-1), -1.0, 1.0)
    distance = 100.0 * np.sqrt(np.square(cells).sum(axis=-1)).mean(axis=-1)
    closeness = np.clip(1.0 - distance / COLOUR_DISTANCE_SCALE, 0.0, 1.0)
    return np.stack((correlation, closeness), axis=-1)
