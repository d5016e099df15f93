"""Where a large object lies, read from one view of its near face and the extent of its class.

A depth camera measures the faces of an object nearest it, so a view's box is centred on what it
saw, not on the object. For a mug that is a centimetre or two; for a bicycle seen end-on, from a
doorway, it is most of the bicycle's length. In `bicycle_wheeled_beside_another` (scenario suite,
network, 7 December 2026) two bicycles standing side by side, 0.65 m apart, were each anchored at
their near ends, 0.8 m from their middles. A later view of either's side, centred on it, then stood
about as far from both anchors, so which of the two it was seemed a matter of how long each had
been unseen (0.87 against 0.66, 0.89 against 0.27, by place alone: the views were cut by the door
frame and no look was compared), and one anchor took the other bicycle's views and, with them, its
symbol.

Boxes are upright and aligned with the world's axes, so the rest of an object seen from one side
lies beyond the view along the horizontal axis nearest the line of sight (the *sight axis*). How
far beyond depends on which way the object stands, which the view itself tells from the class's
known extent (the largest one the robot has seen whole: :func:`.parts.largest_seen_whole`):

- a box about as wide as the object's short side across the sight axis, and clearly shorter than
  its long side along it, shows the object's **end**: the long side runs along the line of sight
  (:func:`long_axis_shown`), and the object's middle lies half its long side beyond the near face
  (less the depth the view did show);
- a box wider than the short side across the sight axis shows the object's **side**: the long side
  runs across, and the middle lies half the short side beyond the face;
- a box narrower than the short side (a piece, cut by a door frame or the image's edge) says
  neither: it stays where it is, as does any view of a small object, of a class not yet seen whole,
  or of one about as long as it is wide (which way it stands cannot be told), or without a
  viewpoint.

A box about as wide as the short side that is also *cut* (by the image's edge, a door frame, an
occluder) reads both ways: an end, or a piece of the side as wide as the object is thick. The two
readings lie most of the long side apart, and the box's width alone flips between them from one
frame to the next: in `large_object_wheeled_away` (network, seed 1, 7 December 2026) one piece of
the wheeled bicycle's side, 0.45 m of it seen across its length (the class's short side 0.37 m),
was read as a side in one frame and as an end in the next, placed 0.75 m beyond the bicycle and
anchored anew, and the search then had two candidates. Measured over three runs of the large-object
scenarios: boxes of true ends 0.27-0.39 m wide (short sides 0.34-0.37 m), side pieces read as ends
0.43-0.45 m, every one cut. So a cut view of that width takes the reading that lands nearer an
anchor of its class (the object it is a part of, where the robot knows it: the camera faces the
side of it that lies nearer); with none within the long side of either reading, it reads as an
end, as a whole view of that width always does (a whole side is as wide as the long side).

Only the centre moves, never the size: what the view showed is still a part, and its look, colour
and extent are judged as a part's (:mod:`.partial_view`). The same reading tells, for the parts
rule, which way an end seen alone says its object stands (:mod:`.parts`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence

import numpy as np

from merlin2_sailor.contract.percept import Percept

#: How far (as a share of the class's short side) a box's width may stray from that side and still
#: show the object's end: boxes of a bicycle's end, 0.35-0.37 m wide, measured 0.27-0.39 m in the
#: scenario suite (7 December 2026): the depth band and the door frame's cut.
END_WIDTH_TOLERANCE = 0.25

#: An object's long side must be at least this many times its short side for a view to tell which
#: way it stands: a box of a dog or a cat, about as long as wide, shows no end.
ELONGATION = 1.5


def long_axis_shown(size: np.ndarray, known: np.ndarray) -> int | None:
    """The horizontal axis (0: x, 1: y) that a box of ``size`` (world axes, m) says its object's long
    side runs along: the box spans about the ``known`` extent's short side across the other axis and
    clearly less than its long side along this one (``known``: the class's
    :func:`~.anchor.turned_extent`). Such a box shows the object's end (seen along its length), or a
    piece of it seen across its thickness; either way its long side runs along this axis. None where
    the box spans the short side on neither axis or on both, or the class is about as long as wide."""
    if not _elongated(known):
        return None
    axes = [along for along in (0, 1) if _shows_an_end(float(size[1 - along]), float(size[along]), known)]
    return axes[0] if len(axes) == 1 else None


def _elongated(known: np.ndarray) -> bool:
    return float(known[0]) >= ELONGATION * float(known[1])


def _shows_an_end(across: float, along: float, known: np.ndarray) -> bool:
    """A box ``across`` m wide about the class's short side and ``along`` m clearly less than its long side."""
    long_side, short_side = float(known[0]), float(known[1])
    return (abs(across - short_side) <= END_WIDTH_TOLERANCE * short_side
            and along < (1.0 - END_WIDTH_TOLERANCE) * long_side)


def object_centre(
    percept: Percept, known: np.ndarray, cut: bool = False, nearby: Sequence[np.ndarray] = ()
) -> np.ndarray:
    """Where the object a view of its near face shows has its middle (world frame, m), given its
    class's ``known`` extent (:func:`~.anchor.turned_extent`): the view's centre, moved away from the
    viewpoint along the sight axis by half the object's depth the view lacks (see the module).
    ``cut``: whether the view is cut (its width may be a piece's); ``nearby``: the centres of the
    anchors of its class, which choose between the readings of a cut view that reads both ways."""
    centre = np.asarray(percept.position, dtype=np.float64).copy()
    if percept.viewpoint is None:
        return centre
    line = centre[:2] - np.asarray(percept.viewpoint, dtype=np.float64)[:2]
    if not np.any(line):
        return centre
    if not _elongated(known):
        return centre
    sight = int(np.argmax(np.abs(line)))
    across, seen_depth = float(percept.size[1 - sight]), float(percept.size[sight])
    long_side, short_side = float(known[0]), float(known[1])

    def beyond(depth: float) -> np.ndarray:
        placed = centre.copy()
        shortfall = depth - seen_depth
        if shortfall > 0.0:
            placed[sight] += math.copysign(shortfall / 2.0, float(line[sight]))
        return placed

    if _shows_an_end(across, seen_depth, known):
        as_end = beyond(long_side)  # its end: as wide as the object, the rest beyond along the line of sight
        return _nearer_anchor(as_end, beyond(short_side), nearby, long_side) if cut else as_end
    if across > (1.0 + END_WIDTH_TOLERANCE) * short_side:
        return beyond(short_side)  # its side
    return centre


def _nearer_anchor(as_end: np.ndarray, as_side: np.ndarray, nearby: Sequence[np.ndarray], reach: float) -> np.ndarray:
    """The reading of a cut view (its end, a piece of its side) nearer an anchor of its class, where
    one stands within ``reach`` of either; else the end's."""
    def distance(centre: np.ndarray) -> float:
        return min((float(np.linalg.norm(centre[:2] - np.asarray(other, dtype=np.float64)[:2])) for other in nearby),
                   default=math.inf)

    to_end, to_side = distance(as_end), distance(as_side)
    if min(to_end, to_side) > reach:
        return as_end
    return as_side if to_side < to_end else as_end


def placed_on_objects(
    percepts: Sequence[Percept], known: Mapping[str, np.ndarray | None], cut: Sequence[bool] | None = None,
    anchors_at: Mapping[str, Sequence[np.ndarray]] | None = None,
) -> tuple[Percept, ...]:
    """The percepts, each centred on its object (:func:`object_centre`) where ``known`` holds an
    extent for its class (None or absent: no large one of it seen whole). ``cut``: per percept,
    whether it is cut (None: none is); ``anchors_at``: per class, its anchors' centres."""
    placed = []
    for row, percept in enumerate(percepts):
        extent = known.get(percept.class_name)
        nearby = () if anchors_at is None else anchors_at.get(percept.class_name, ())
        centre = None if extent is None else object_centre(
            percept, extent, cut=bool(cut[row]) if cut is not None else False, nearby=nearby)
        if centre is None or np.array_equal(centre, percept.position):
            placed.append(percept)
        else:
            placed.append(dataclasses.replace(percept, position=centre))
    return tuple(placed)
