"""An anchor's appearance gallery: a few of its views' embeddings, stored compactly as bfloat16.

A 1,280-d float32 embedding takes 5 kB; 10,000 anchors with four views each would take 200 MB.
Galleries are therefore stored as bfloat16 (the upper 16 bits of the float32, rounded to nearest
even), halving that. bfloat16 rather than float16 because turning it back into float32 is an
integer shift NumPy vectorises (NumPy's float16 conversion is ~10x slower, and the matching
table converts every candidate's gallery each frame), and because it keeps float32's range. Its
~0.4 % relative precision is far below the differences between two objects' features.
"""

from __future__ import annotations

import math

import numpy as np

from merlin2_sailor.errors import InvalidInputError

#: How galleries are stored: the bit patterns of bfloat16 numbers.
GALLERY_DTYPE = np.uint16


def to_bfloat16_bits(values: np.ndarray) -> np.ndarray:
    """Round float32 values to bfloat16 (nearest, ties to even) and return their bits."""
    bits = np.ascontiguousarray(values, dtype=np.float32).view(np.uint32)
    rounding = ((bits >> 16) & 1) + np.uint32(0x7FFF)
    return ((bits + rounding) >> 16).astype(GALLERY_DTYPE)


def from_bfloat16_bits(bits: np.ndarray) -> np.ndarray:
    """The float32 values of bfloat16 bit patterns."""
    return (np.asarray(bits, dtype=GALLERY_DTYPE).astype(np.uint32) << 16).view(np.float32)


def add_to_gallery(gallery: np.ndarray | None, embedding: np.ndarray, size: int) -> np.ndarray:
    """Append an embedding, keeping the last ``size``; returns a new (n, D) array of bits."""
    row = to_bfloat16_bits(np.asarray(embedding).reshape(1, -1))
    if gallery is None or gallery.shape[0] == 0:
        return row
    _check_dimension(gallery, row.shape[1])
    return np.concatenate((gallery[max(0, len(gallery) - size + 1) :], row))


def _check_dimension(gallery: np.ndarray, dimension: int) -> None:
    if gallery.shape[1] != dimension:
        raise InvalidInputError(
            f"An embedding of dimension {dimension} cannot join a gallery of dimension {gallery.shape[1]}; "
            "the backbone changed while anchors existed. Forget the anchors or keep one backbone."
        )


def add_view(
    gallery: np.ndarray | None, scales: np.ndarray | None, embedding: np.ndarray, scale: float, size: int
) -> tuple[np.ndarray, np.ndarray]:
    """Add a view to a gallery of at most ``size``, keeping beside it the size in pixels of each
    view's box (``scale``: the square root of its area; NaN where unknown, as for a gallery
    restored from a snapshot that did not keep sizes). Returns the new (gallery, scales); the new
    view is always kept, last.

    A full gallery gives up the view *nearest in size* to the new one, not the oldest: views of
    one size are refreshed, views of other sizes stay. Keeping only the last views, an object the
    robot drove away from kept nothing but its farthest, blurred views (19-26 px boxes where the
    robot had seen it at 50); moved beside another mug and seen again from the living room at
    27-36 px, the red mug's new anchor scored 0.25-0.39 against its own lost anchor in each of the
    37 times a search judged it, which therefore ended "not found" with the mug in the house
    (scenario suite, ``moved_beside_other_colour``, network, seed 8, 5 December 2026; in seed 1's
    failure too the lost anchor held only 21-24 px views), where the runs that found it scored
    0.69-0.74. A gallery of several sizes also keeps what :mod:`.far_view` needs: views as small as a
    far percept, once seen, stay until a view of their size replaces them. Where a size is
    unknown, the oldest view goes, as before sizes were kept."""
    kept_scales = view_scales(gallery, scales)
    if gallery is not None and len(gallery) >= size and _sizes_known(kept_scales, scale):
        _check_dimension(gallery, np.asarray(embedding).size)
        nearest = int(np.argmin(np.abs(np.log(kept_scales) - math.log(scale))))
        gallery = np.delete(gallery, nearest, axis=0)
        kept_scales = np.delete(kept_scales, nearest)
    new_gallery = add_to_gallery(gallery, embedding, size)
    new_scales = np.append(kept_scales, np.float32(scale))[-len(new_gallery):].astype(np.float32)
    return new_gallery, new_scales


def _sizes_known(scales: np.ndarray, scale: float) -> bool:
    return bool(np.isfinite(scales).all() and (scales > 0.0).all() and math.isfinite(scale) and scale > 0.0)


def view_scales(gallery: np.ndarray | None, scales: np.ndarray | None) -> np.ndarray:
    """(n,) float32 sizes of a gallery's n views: ``scales``, or NaN (unknown) where they do not
    describe the gallery (none kept, or another length)."""
    count = 0 if gallery is None else len(gallery)
    if scales is not None and len(scales) == count:
        return np.asarray(scales, dtype=np.float32)
    return np.full(count, np.nan, dtype=np.float32)


def gallery_similarity(first: np.ndarray, second: np.ndarray) -> float:
    """The best cosine similarity between any view of one gallery and any view of the other."""
    a = from_bfloat16_bits(first).astype(np.float64)
    b = from_bfloat16_bits(second).astype(np.float64)
    a /= np.maximum(np.linalg.norm(a, axis=1, keepdims=True), 1e-12)
    b /= np.maximum(np.linalg.norm(b, axis=1, keepdims=True), 1e-12)
    return float(np.max(a @ b.T))
