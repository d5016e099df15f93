"""A crop's colours as two small histograms: what an ImageNet backbone's pooled features blur away.

The backbone's features say "a mug seen from above" so strongly that a red, a blue and a green
mug of one make lie closer in them than one mug seen from two sides (measured on the demo's
house: median L1 180-230 between the red mug and its look-alikes, 208 between views of the red
mug itself). Colour tells them apart at once, and it is what a person would use. So every crop
embedding ends with this descriptor, followed by the crop's layout (see :mod:`.crop_descriptor`),
and the matching network compares
the descriptors of a percept and an anchor as a feature of its own (see
:mod:`merlin2_sailor.anchoring.matching_network`).

The descriptor is a histogram of the crop's centre (the middle half of its width and height)
followed by one of its surround (the rest). One histogram of the whole crop is not enough: an
object's distinguishing colour is often at its outline (a mug's rim, a book's cover edge) while
its middle is shared with its look-alikes (the coffee in every mug), and the shared part swamps
the rest. Measured on the demo's mugs, the histogram intersection of the whole crops was 0.89
between views of the red mug and 0.68-0.73 between it and the green mugs; of the surrounds, 0.88
and 0.39-0.42, while the centres still tell a white mug from a book (0.0-0.1).

Layout of each histogram (:data:`COLOUR_BINS` values, summing to 1): :data:`HUE_BINS` bins of
hue for the chromatic pixels (saturation and brightness above :data:`CHROMATIC_SATURATION` /
:data:`CHROMATIC_VALUE`), then :data:`GREY_BINS` bins of brightness for the others (dark, mid,
light), so a white mug and a black one differ too. Each chromatic pixel is shared between its
two nearest hue bins (linear interpolation around the hue circle), so a hue on a bin's edge
does not flip between bins from one frame to the next.
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from merlin2_sailor.errors import InvalidInputError
from merlin2_sailor.perception.rgb_crop import checked_rgb_crop

#: Hue bins of 20 degrees each.
HUE_BINS = 18
#: Brightness bins of the pixels too grey or too dark to have a hue.
GREY_BINS = 3
#: Values per histogram.
COLOUR_BINS = HUE_BINS + GREY_BINS
#: Histograms per descriptor: the crop's centre, then its surround.
COLOUR_REGIONS = 2
#: Values per descriptor, the length of the colour part of an embedding.
COLOUR_DESCRIPTOR_SIZE = COLOUR_REGIONS * COLOUR_BINS
#: The centre leaves this fraction of the crop's width (height) out on each side.
CENTRE_MARGIN = 0.25
#: A pixel has a hue when its saturation and value (0..1) are both above these.
CHROMATIC_SATURATION = 0.25
CHROMATIC_VALUE = 0.2
#: Crops are shrunk to at most this many pixels a side first: the histograms do not need more,
#: and a close-up's million pixels would cost milliseconds.
MAXIMUM_SIDE = 64


def colour_histogram(pixels: np.ndarray) -> np.ndarray:
    """The (COLOUR_BINS,) float32 histogram of (..., 3) uint8 RGB pixels (see the module docstring)."""
    pixels = np.asarray(pixels)
    if pixels.dtype != np.uint8 or pixels.ndim < 2 or pixels.shape[-1] != 3 or pixels.size == 0:
        raise InvalidInputError(
            "A colour histogram needs non-empty uint8 RGB pixels (..., 3), "
            f"got shape {pixels.shape} and dtype {pixels.dtype}."
        )
    row = np.ascontiguousarray(pixels.reshape(1, -1, 3))
    hsv = cv2.cvtColor(row, cv2.COLOR_RGB2HSV_FULL).reshape(-1, 3).astype(np.float32)
    hue = hsv[:, 0] * (HUE_BINS / 256.0)  # OpenCV's full range maps 360 degrees onto 0..255
    saturation = hsv[:, 1] / 255.0
    value = hsv[:, 2] / 255.0
    chromatic = (saturation > CHROMATIC_SATURATION) & (value > CHROMATIC_VALUE)
    # Bin centres sit at i + 0.5; share each hue between the two centres around it. (bincount,
    # not np.add.at: the same sums, a tenth of the time.)
    position = hue[chromatic] - 0.5
    lower = np.floor(position)
    upper_share = (position - lower).astype(np.float64)
    lower_bin = lower.astype(np.intp) % HUE_BINS
    grey_bin = np.minimum((value[~chromatic] * GREY_BINS).astype(np.intp), GREY_BINS - 1)
    histogram = (np.bincount(lower_bin, weights=1.0 - upper_share, minlength=COLOUR_BINS)
                 + np.bincount((lower_bin + 1) % HUE_BINS, weights=upper_share, minlength=COLOUR_BINS)
                 + np.bincount(HUE_BINS + grey_bin, minlength=COLOUR_BINS))
    return (histogram / histogram.sum()).astype(np.float32)


#: An object's colour is read from at most this many of its pixels (an even subsample beyond).
MAXIMUM_OBJECT_PIXELS = MAXIMUM_SIDE * MAXIMUM_SIDE
#: Fewer object pixels than this say too little about its colour: no histogram. A far object's
#: few pixels are mostly its outline, blended with what is behind it: measured on the demo's tours,
#: views of about 100-150 pixels (a mug 4 m away) differed from their own anchor's colour in one of
#: seven; above 200 the house's tours over three seeds split no object more than without colour, while
#: a floor of 600 left the mugs the robot sees from across a room without a colour at all (the swapped
#: and removed scenarios went wrong again).
MINIMUM_OBJECT_PIXELS = 200


def object_colour(crop: np.ndarray, pixels: np.ndarray) -> np.ndarray | None:
    """The (COLOUR_BINS,) histogram of the crop's pixels that ``pixels`` (a boolean image of the
    crop's size) marks as the object's own, or None when they are too few to tell a colour.

    Unlike :func:`colour_descriptor`, which reads the whole crop, nothing of the background the
    2D box also covers (the wall, the table, a neighbour) enters it, so two mugs of one make
    differ only by their own colours (see :mod:`merlin2_sailor.anchoring.colour_evidence`)."""
    crop = np.asarray(crop)
    pixels = np.asarray(pixels, dtype=bool)
    if pixels.shape != crop.shape[:2]:
        raise InvalidInputError(f"object pixels {pixels.shape} do not match the crop {crop.shape[:2]}")
    count = int(np.count_nonzero(pixels))
    if count < MINIMUM_OBJECT_PIXELS:
        return None
    # Thin out a close-up on a regular grid before gathering its pixels: gathering all of a
    # 400 x 400 crop's cost 3 ms, the histogram needs no more than a few thousand.
    step = max(1, math.isqrt(count // MAXIMUM_OBJECT_PIXELS))
    chosen = crop[::step, ::step][pixels[::step, ::step]]
    return colour_histogram(chosen) if len(chosen) else None


def object_colour_similarity(first: np.ndarray, second: np.ndarray) -> float:
    """Histogram intersection of two object colours (1: the same colours, 0: none shared)."""
    return float(np.minimum(np.asarray(first, dtype=np.float64), np.asarray(second, dtype=np.float64)).sum())


def colour_descriptor(crop: np.ndarray) -> np.ndarray:
    """(COLOUR_DESCRIPTOR_SIZE,) float32: the histogram of one (H, W, 3) uint8 RGB crop's centre,
    then of its surround (a crop too small to have both uses the whole crop for both)."""
    crop = checked_rgb_crop(crop, "A colour descriptor")
    longest = max(crop.shape[:2])
    if longest > MAXIMUM_SIDE:
        scale = MAXIMUM_SIDE / longest
        size = (max(1, round(crop.shape[1] * scale)), max(1, round(crop.shape[0] * scale)))
        crop = cv2.resize(crop, size, interpolation=cv2.INTER_AREA)
    height, width = crop.shape[:2]
    top, left = int(height * CENTRE_MARGIN), int(width * CENTRE_MARGIN)
    bottom, right = height - top, width - left
    if top < 1 or left < 1:  # a sliver: no surround of its own
        whole = colour_histogram(crop)
        return np.concatenate([whole, whole])
    surround = np.ones((height, width), dtype=bool)
    surround[top:bottom, left:right] = False
    return np.concatenate([colour_histogram(crop[top:bottom, left:right]), colour_histogram(crop[surround])])


def colour_similarity(descriptor_difference: np.ndarray) -> np.ndarray:
    """Per region, the histogram intersection of two descriptors from their (..., SIZE) element-wise
    absolute difference: (..., COLOUR_REGIONS) values, 1 for the same colours, 0 for none shared
    (for histograms summing to 1, the intersection is 1 - L1 / 2)."""
    difference = np.asarray(descriptor_difference, dtype=np.float64)
    regions = difference.reshape(*difference.shape[:-1], COLOUR_REGIONS, COLOUR_BINS)
    return np.clip(1.0 - regions.sum(axis=-1) / 2.0, 0.0, 1.0)
