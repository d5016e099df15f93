"""The one check every consumer of a crop makes before reading its pixels.

A crop reaches the colour histogram, the layout thumbnail and the backbone from a percept message
or a bag, where a wrong encoding or an empty box is possible; each would otherwise fail deep in
OpenCV with a message naming none of them. One check, one message.
"""

from __future__ import annotations

import numpy as np

from merlin2_sailor.errors import InvalidInputError


def checked_rgb_crop(crop: np.ndarray, what: str) -> np.ndarray:
    """``crop`` as an array, when it is a non-empty (H, W, 3) uint8 RGB image; otherwise an
    :class:`InvalidInputError` saying that ``what`` (e.g. "A colour descriptor") needs one."""
    crop = np.asarray(crop)
    if crop.ndim != 3 or crop.shape[2] != 3 or crop.dtype != np.uint8 or crop.shape[0] < 1 or crop.shape[1] < 1:
        raise InvalidInputError(
            f"{what} needs a non-empty (H, W, 3) uint8 RGB crop, got shape {crop.shape} and dtype {crop.dtype}."
        )
    return crop
