"""The integer pixel window a 2D box covers, clamped to the image.

The 3D box estimate and the crop must read exactly the same pixels, or a percept's appearance and
its geometry describe different things; one function decides which pixels a box covers.
Detector boxes use edge coordinates (the image spans [0, width] x [0, height]), so pixel ``i``
belongs to a box when the box overlaps the interval [i, i + 1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from merlin2_sailor.contract.percept import BoundingBox2D


@dataclass(frozen=True, slots=True)
class PixelWindow:
    """Rows ``row_start:row_stop`` and columns ``column_start:column_stop`` of an image."""

    row_start: int
    row_stop: int
    column_start: int
    column_stop: int

    @property
    def height(self) -> int:
        return self.row_stop - self.row_start

    @property
    def width(self) -> int:
        return self.column_stop - self.column_start

    @property
    def slices(self) -> tuple[slice, slice]:
        """Index an image with ``image[window.slices]``."""
        return slice(self.row_start, self.row_stop), slice(self.column_start, self.column_stop)


def pixel_window(box: BoundingBox2D, image_width: int, image_height: int) -> PixelWindow | None:
    """Return the pixels ``box`` covers inside the image, or None when it covers none.

    Boxes partly outside the image are clamped; boxes with non-finite or non-positive size, or
    lying entirely outside, have no window.
    """
    x_min, y_min, x_max, y_max = box.corners
    if not all(math.isfinite(value) for value in (x_min, y_min, x_max, y_max)):
        return None
    if x_max <= x_min or y_max <= y_min:
        return None
    column_start = max(0, math.floor(x_min))
    column_stop = min(image_width, math.ceil(x_max))
    row_start = max(0, math.floor(y_min))
    row_stop = min(image_height, math.ceil(y_max))
    if column_stop <= column_start or row_stop <= row_start:
        return None
    return PixelWindow(row_start, row_stop, column_start, column_stop)
