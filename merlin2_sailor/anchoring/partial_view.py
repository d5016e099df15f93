"""Is a percept a partial view of its object? Cut by the image's edge, or by something in front.

A percept's position is the middle of the object's points the camera saw. When part of the
object is outside the picture, or hidden behind a door frame or a table, that middle is the
middle of the part in view, off by up to half the object's extent: a television seen past a
door frame is anchored at its near end. Such a view still proves the object is there (it keeps
the anchor alive), but it should barely move the anchor (see ``FusionConfig.partial_view_variance_factor``).

Two tests, both cheap: the 2D box comes within ``edge_margin`` pixels of the image's edge; or,
with a depth image, a strip of pixels just outside the left, right or top side of the box is
clearly nearer than the object's front (its centre's depth less half its extent, less
``occluder_margin`` metres), so the object goes on behind an occluder there. The bottom side is
not asked: what is just below an object in the picture is mostly what it stands on, a little
nearer than it by nature. A strip without depth proves nothing.

Neither test sees an object hidden by a thin wall just in front of it (a television behind a
door frame's wall): for a large object already seen whole (twice: one box may be a detector's
slip around two neighbours), a view much smaller than what the anchor knows of it is taken as
partial too (:func:`smaller_than_known`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.anchoring.anchor import Anchor, turned_extent
from merlin2_sailor.anchoring.features import SMALL_OBJECT_EXTENT
from merlin2_sailor.anchoring.visibility import CameraView
from merlin2_sailor.contract.percept import Percept
from merlin2_sailor.errors import ConfigurationError


@dataclass(frozen=True, slots=True)
class PartialViewConfig:
    """``edge_margin`` (pixels), ``occluder_margin`` (m) and ``strip_width`` (pixels): see the module."""

    edge_margin: float = 4.0
    occluder_margin: float = 0.15
    strip_width: int = 3

    def __post_init__(self) -> None:
        if not (math.isfinite(self.edge_margin) and self.edge_margin >= 0.0):
            raise ConfigurationError(f"partial view edge_margin must be >= 0 pixels, got {self.edge_margin}.")
        if not (math.isfinite(self.occluder_margin) and self.occluder_margin > 0.0):
            raise ConfigurationError(
                f"partial view occluder_margin must be a positive number of metres, got {self.occluder_margin}."
            )
        if self.strip_width < 1:
            raise ConfigurationError(f"partial view strip_width must be at least 1 pixel, got {self.strip_width}.")


def partial_views(percepts: Sequence[Percept], camera: CameraView | None, config: PartialViewConfig) -> list[bool]:
    """For each percept, whether it is a partial view (all False without a camera)."""
    if camera is None or not percepts:
        return [False] * len(percepts)
    width, height = camera.intrinsics.width, camera.intrinsics.height
    flags = [_touches_edge(percept.box.corners, width, height, config.edge_margin) for percept in percepts]
    if camera.depth is None:
        return flags
    depth = np.asarray(camera.depth)
    positions = np.array([percept.position for percept in percepts], dtype=np.float64).reshape(-1, 3)
    object_depths = camera.camera_to_world.inverse().transform_points(positions)[:, 2]
    for index, percept in enumerate(percepts):
        if not flags[index]:
            front = float(object_depths[index]) - 0.5 * float(np.max(percept.size[:2]))
            flags[index] = _occluded_at_a_side(percept.box.corners, depth, front, config)
    return flags


#: A view of a large object whose footprint is under this share of the footprint the anchor
#: knows from whole views is a partial view.
PARTIAL_FOOTPRINT_SHARE = 0.6

#: Whole views an anchor needs before its extent says that later, smaller views are parts of it.
#: One is not enough: a detector's single box around two neighbours (scenario suite, `twin_moved`,
#: network, seed 4, 5 December 2026: a "cup" box spanning the hall's mug and the book 0.5 m beside
#: it) made a cup anchor 0.68 m long, and every later view of the real mug, a fifth of that, was
#: taken as a part of it, so the false anchor was confirmed by the mug's views and frozen at its
#: false extent, and the mug's own anchor went missing beside it, one object under two symbols.
#: Two whole views of a truly large object come within a frame or two of each other.
EXTENT_CORROBORATING_VIEWS = 2


def smaller_than_known(percept: Percept, anchor: Anchor) -> bool:
    """Whether a percept shows clearly less of a large object than the anchor's whole views did."""
    return bool(_shows_less(np.asarray(percept.size, dtype=np.float64).reshape(1, 3), [anchor])[0, 0])


#: A view whose box spans at least this share of the largest whole one of its class, along its
#: footprint and up, shows the whole object, whatever the cut tests say (see :func:`spans_known_whole`).
WHOLE_EXTENT_SHARE = 0.9


def spans_known_whole(size: np.ndarray, known: np.ndarray | None) -> bool:
    """Whether a box of ``size`` spans the ``known`` extent of its class's largest whole one
    (:func:`~.anchor.turned_extent`; None: none seen), its length and its height, within
    ``WHOLE_EXTENT_SHARE``: a view that shows all of the object lacks nothing, though a nearer
    surface stands beside it or the image's edge touches its box. The two bicycles of
    `bicycle_wheeled_beside_another` stand 0.3 m apart; a whole view of one, 1.64 m of its 1.6, had
    the other beside it, nearer the camera, and was taken as cut (scenario suite, network, 7 December
    2026): its look and colour never counted, its anchor kept the box of its end, and a search could
    never compare it with the bicycle it sought."""
    if known is None:
        return False
    extent = turned_extent(np.asarray(size, dtype=np.float64))
    return bool(extent[0] >= WHOLE_EXTENT_SHARE * float(known[0]) and extent[2] >= WHOLE_EXTENT_SHARE * float(known[2]))


def comparable_views(sizes: np.ndarray, whole: Sequence[bool] | None, anchors: Sequence[Anchor]) -> np.ndarray:
    """(P, A) bool: whether views of the (P, 3) ``sizes`` may be compared by their look with each
    anchor's views.

    A partial view (``whole`` False: cut by the image's edge or an occluder; or clearly less of a
    large object than the anchor's whole views showed) looks like a part, not like the object:
    its crop is no evidence for or against the object's appearance, so such a pair is scored
    without it (a learned matcher falls back to the rules, which forgive a part's place by the
    object's extent) and it never joins an appearance gallery. Measured on the scenario suite
    (3 December 2026): the network's duplicate anchors were all of large objects (TV, bicycle,
    cat) whose second anchor began with views of a quarter to two thirds of the first's extent,
    and scored 0.99-1.0 against it once whole views came. ``whole`` None: not known (no camera),
    so only the extent tells.
    """
    comparable = ~_shows_less(np.asarray(sizes, dtype=np.float64).reshape(-1, 3), anchors)
    if whole is not None:
        comparable &= np.asarray(whole, dtype=bool).reshape(-1, 1)
    return comparable


#: A single view's colour is held to a large anchor's only where each shows at least this share of
#: the other's height and of its footprint (see :func:`colour_comparable_views`).
COLOUR_EXTENT_SHARE = 0.8


def colour_comparable_views(sizes: np.ndarray, whole: Sequence[bool] | None, anchors: Sequence[Anchor],
                            comparable: np.ndarray | None = None) -> np.ndarray:
    """(P, A) bool: whether the colour of views of the (P, 3) ``sizes`` may be held to each anchor's.

    As :func:`comparable_views`, and more: a large object's view and its anchor's whole views must
    show about as much of it, its height as well as its footprint, whichever side saw less (each at
    least ``COLOUR_EXTENT_SHARE`` of the other's). Why: the colour of a part is not the object's,
    and a part is not always told by the image's edge or an occluder beside the box: the lower part
    of a dog hidden behind furniture, or a dog seen end-on, whose box holds all there is to see of
    it. In the scenario suite (network, 6 December 2026) three of the five duplicate anchors were the
    dog's, each made by a view ruled out by colour in a grey window where one side had seen less of
    the dog than the other: the anchor's first three views 0.36 m tall (or 0.33 m long) against the
    whole dog's 0.52 m (0.56 m), or the ruling view 0.40 m tall against the anchor's 0.52 m. On
    tours of 60 held-out generated houses (``scripts/view_extents.py``), a large object's whole view
    showing 0.5-0.7 of the object's height or footprint was ruled out by the colour of the object's
    own fullest views 2-3 % of the time, one showing 0.8-0.9 of it 0.9 %. Such a view still counts
    for the matcher, and is fused, as before. ``comparable``: :func:`comparable_views` of the same
    views, where the caller has it already.
    """
    if comparable is None:
        comparable = comparable_views(sizes, whole, anchors)
    return comparable & ~_shows_another_extent(np.asarray(sizes, dtype=np.float64).reshape(-1, 3), anchors)


def _shows_another_extent(sizes: np.ndarray, anchors: Sequence[Anchor]) -> np.ndarray:
    """(P, A) bool: a view and an anchor of a large object (over ``SMALL_OBJECT_EXTENT`` along any
    axis, height included: a dog known only end-on is 0.27 m long but 0.52 m tall; its extent known
    from at least ``EXTENT_CORROBORATING_VIEWS`` whole views) of which one shows under
    ``COLOUR_EXTENT_SHARE`` of the other's height or footprint. Only the anchor tells what is large:
    a far view of a mug measured 0.3-0.44 m long by depth noise (tours of the suite's worlds) must
    still be held to the mug's colour, or a look-alike of another colour would take its anchor."""
    known = np.array([a.whole_views >= EXTENT_CORROBORATING_VIEWS and float(np.max(a.size)) > SMALL_OBJECT_EXTENT
                      for a in anchors], dtype=bool)
    result = np.zeros((sizes.shape[0], len(anchors)), dtype=bool)
    if not known.any():
        return result
    anchor_extents = np.array([[float(np.max(a.size[:2])), float(a.size[2])] for a in anchors])
    view_extents = np.column_stack([np.max(sizes[:, :2], axis=1), sizes[:, 2]])
    ratio = view_extents[:, np.newaxis, :] / np.maximum(anchor_extents[np.newaxis, :, :], 1e-9)
    differs = ((ratio < COLOUR_EXTENT_SHARE) | (ratio * COLOUR_EXTENT_SHARE > 1.0)).any(axis=2)
    return differs & known[np.newaxis, :]


def _shows_less(sizes: np.ndarray, anchors: Sequence[Anchor]) -> np.ndarray:
    """(P, A) bool: a view's footprint under ``PARTIAL_FOOTPRINT_SHARE`` of a large anchor's known one
    (known from at least ``EXTENT_CORROBORATING_VIEWS`` whole views)."""
    known = np.array([float(np.max(a.size[:2])) if a.whole_views >= EXTENT_CORROBORATING_VIEWS else 0.0
                      for a in anchors]).reshape(1, -1)
    extent = np.max(sizes[:, :2], axis=1).reshape(-1, 1)
    return (known > SMALL_OBJECT_EXTENT) & (extent < PARTIAL_FOOTPRINT_SHARE * known)


def _touches_edge(corners: tuple[float, float, float, float], width: int, height: int, margin: float) -> bool:
    x_min, y_min, x_max, y_max = corners
    return x_min <= margin or y_min <= margin or x_max >= width - margin or y_max >= height - margin


def _occluded_at_a_side(
    corners: tuple[float, float, float, float], depth: np.ndarray, front_depth: float, config: PartialViewConfig
) -> bool:
    """Whether, beside the left, right or top side of the box, the depth is clearly nearer than the object's front."""
    height, width = depth.shape
    x_min, y_min, x_max, y_max = (int(round(value)) for value in corners)
    x_min, x_max = max(x_min, 0), min(x_max, width)
    y_min, y_max = max(y_min, 0), min(y_max, height)
    if x_max <= x_min or y_max <= y_min:
        return False
    strip = config.strip_width
    sides = (
        depth[y_min:y_max, max(x_min - strip, 0):x_min],  # left
        depth[y_min:y_max, x_max:min(x_max + strip, width)],  # right
        depth[max(y_min - strip, 0):y_min, x_min:x_max],  # above
    )
    nearer_than = front_depth - config.occluder_margin
    for side in sides:
        values = side[np.isfinite(side) & (side > 0.0)]
        if values.size and float(np.median(values)) < nearer_than:
            return True
    return False
