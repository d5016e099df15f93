"""What ends every crop embedding after the backbone's features: the crop's colours and layout.

The backbone's pooled features say what kind of thing a crop shows; two look-alikes of one class
differ in what they blur away: colour (:mod:`.colour_histogram`, the histograms of the crop's
centre and surround) and where it is (:mod:`.layout_thumbnail`, a 6 x 6 thumbnail). Both are
appended to the embedding, so they travel with it (anchors' galleries, percept messages, the
embedding cache) and cost nothing to compare; the matching network reads them as
:data:`DESCRIPTOR_SIMILARITIES` similarities from the embeddings' difference, through
:func:`descriptor_similarity`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from merlin2_sailor.perception.colour_histogram import (
    COLOUR_DESCRIPTOR_SIZE,
    COLOUR_REGIONS,
    colour_descriptor,
    colour_similarity,
)
from merlin2_sailor.perception.layout_thumbnail import (
    LAYOUT_SIMILARITIES,
    LAYOUT_SIZE,
    layout_descriptor,
    layout_similarity,
)

#: Values per descriptor: the colour histograms, then the layout.
DESCRIPTOR_SIZE = COLOUR_DESCRIPTOR_SIZE + LAYOUT_SIZE
#: Similarities read from a pair of descriptors: one per colour region, then the layout's.
DESCRIPTOR_SIMILARITIES = COLOUR_REGIONS + LAYOUT_SIMILARITIES


def crop_descriptor(crop: np.ndarray) -> np.ndarray:
    """(DESCRIPTOR_SIZE,) float32 descriptor of one (H, W, 3) uint8 RGB crop."""
    return np.concatenate([colour_descriptor(crop), layout_descriptor(crop)])


def crop_descriptors(crops: Sequence[np.ndarray]) -> np.ndarray:
    """(N, DESCRIPTOR_SIZE) descriptors of N crops; an empty list gives a (0, size) array."""
    descriptors = np.empty((len(crops), DESCRIPTOR_SIZE), dtype=np.float32)
    for row, crop in enumerate(crops):
        descriptors[row] = crop_descriptor(crop)
    return descriptors


def descriptor_similarity(descriptor_difference: np.ndarray) -> np.ndarray:
    """(..., DESCRIPTOR_SIMILARITIES) similarities of two descriptors from their (..., DESCRIPTOR_SIZE)
    element-wise absolute difference: the colour regions' histogram intersections, then the
    layout's lightness correlation and colour closeness."""
    difference = np.asarray(descriptor_difference, dtype=np.float64)
    colour = colour_similarity(difference[..., :COLOUR_DESCRIPTOR_SIZE])
    layout = layout_similarity(difference[..., COLOUR_DESCRIPTOR_SIZE:])
    return np.concatenate([colour, layout], axis=-1)
