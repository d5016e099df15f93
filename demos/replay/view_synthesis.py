"""New views of a real RGB-D frame, as seen by the same camera moved sideways.

A camera translated by ``shift`` metres along its own x axis sees a point at depth z moved by
``-f * shift / z`` pixels along the image row, and nothing else changes: this is how the two
views of a rectified stereo pair differ. Each pixel is moved by that amount with its depth, the
nearest surface winning where several land on one pixel (a z-buffer). What the first view could
not see (disocclusions, a strip beside each foreground edge) is filled from the background side
of the row, the usual rule of depth-image-based rendering. Filled pixels get colour, but their
depth stays unknown (NaN): only measured depths are ever reported as depth.
"""

from __future__ import annotations

import numpy as np


def background_fill_columns(known: np.ndarray, depth: np.ndarray) -> np.ndarray:
    """For each pixel, the column of the row's pixel its value should come from.

    Known pixels point at themselves; an unknown one points at the nearest known pixel on its
    left or on its right, whichever is farther from the camera (larger ``depth``), or the only
    one there is. A row with no known pixel gives -1.
    """
    height, width = known.shape
    columns = np.broadcast_to(np.arange(width), (height, width))
    left = np.maximum.accumulate(np.where(known, columns, -1), axis=1)
    right = np.minimum.accumulate(np.where(known, columns, width)[:, ::-1], axis=1)[:, ::-1]
    rows = np.arange(height)[:, np.newaxis]
    left_depth = np.where(left >= 0, depth[rows, np.clip(left, 0, width - 1)], -np.inf)
    right_depth = np.where(right < width, depth[rows, np.clip(right, 0, width - 1)], -np.inf)
    chosen = np.where(left_depth >= right_depth, left, right)
    chosen = np.where((left < 0) & (right >= width), -1, chosen)
    return np.where(known, columns, chosen)


def translate_view(
    color: np.ndarray, depth_metres: np.ndarray, focal_pixels: float, shift_metres: float
) -> tuple[np.ndarray, np.ndarray]:
    """The (colour, depth) the camera would see moved ``shift_metres`` along its x axis (to the right).

    ``depth_metres`` is registered to ``color``, NaN where unknown. A shift of zero returns copies
    of the inputs.
    """
    color = np.asarray(color)
    depth = np.asarray(depth_metres, dtype=np.float32)
    if shift_metres == 0.0:
        return color.copy(), depth.copy()
    height, width = depth.shape
    measured = np.isfinite(depth) & (depth > 0.0)
    # Pixels without a measured depth still have a colour to carry: they move with the
    # background beside them (the disparity map's gaps are mostly occluded background).
    rows = np.arange(height)[:, np.newaxis]
    source_columns = background_fill_columns(measured, np.where(measured, depth, -np.inf))
    carried = np.where(source_columns >= 0, depth[rows, np.clip(source_columns, 0, width - 1)], np.nan)
    movable = np.isfinite(carried)
    target = np.rint(np.arange(width)[np.newaxis, :] - focal_pixels * shift_metres / np.where(movable, carried, 1.0))
    movable &= (target >= 0) & (target < width)

    source_rows, source_cols = np.nonzero(movable)
    target_index = source_rows * width + target[movable].astype(np.intp)
    z = carried[movable]
    order = np.lexsort((z, target_index))  # per target pixel, nearest first
    first = np.ones(order.size, dtype=bool)
    first[1:] = target_index[order[1:]] != target_index[order[:-1]]
    winners = order[first]

    z_buffer = np.full(height * width, np.nan, dtype=np.float32)
    z_buffer[target_index[winners]] = z[winners]
    new_depth = np.full(height * width, np.nan, dtype=np.float32)
    new_depth[target_index[winners]] = np.where(
        measured[source_rows[winners], source_cols[winners]], z[winners], np.nan
    )
    new_color = np.zeros((height * width, 3), dtype=color.dtype)
    new_color[target_index[winners]] = color[source_rows[winners], source_cols[winners]]
    z_buffer, new_depth, new_color = (
        z_buffer.reshape(height, width), new_depth.reshape(height, width), new_color.reshape(height, width, 3)
    )

    covered = np.isfinite(z_buffer)
    fill = background_fill_columns(covered, np.where(covered, z_buffer, -np.inf))
    holes = ~covered & (fill >= 0)
    hole_rows, hole_cols = np.nonzero(holes)
    new_color[hole_rows, hole_cols] = new_color[hole_rows, fill[hole_rows, hole_cols]]
    return new_color, new_depth
