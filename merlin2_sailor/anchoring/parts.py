"""Two anchors of a large object's class that are parts of one object: the camera saw it in pieces.

A bicycle first seen where it was wheeled to, past a door frame, from its side, close up, shows
the camera a wheel, then its middle, then its other end: each view is a part, its box a third of
the bicycle, its crop unlike the others, and a view that falls far enough from the part anchored
before it is anchored anew. Nothing else joins such anchors: they are both confirmed (the
reappearance and same-space rules join a MISSING anchor with one seen in its place), no view of
either is comparable by its look with the other's (:func:`~.partial_view.comparable_views`), and
the matching function scores a part's view low against another part (0.03-0.46 for the bicycle
of `large_object_wheeled_away`, scenario suite, 5 December 2026: three confirmed anchors 0.5-1.3 m
apart, and a search for the bicycle then said it "cannot tell" them apart, where the truth was one
bicycle).

Two parts of one object differ from two objects by evidence of space and time, not of look:

- **they fit inside one object**: the box around both fits, side by side, within the largest
  extent the robot has seen whole of their class (an anchor of the class with at least
  :data:`~.partial_view.EXTENT_CORROBORATING_VIEWS` whole views, as :mod:`.partial_view` asks
  before a view is called a part), with a share ``slack`` more for the noise of boxes (a part's
  box, centred on what the depth camera saw of it, reaches past the object by a few decimetres).
  Across the box's long side, boxes shifted sideways count as wide as the wider one while they
  share some of their width (:func:`extent_of_both`): views from two sides, and the error of a
  box, shift them so. Two whole bicycles side by side, or two cats nose to tail, make a box larger
  than one: they are never joined.
  Where the robot has not seen a whole one of the class, nothing is joined: there is no evidence
  of how large one is;
- **one of them, at least, is a part**: its footprint is clearly less than the whole one's (under
  :data:`~.partial_view.PARTIAL_FOOTPRINT_SHARE` of it, as :mod:`.partial_view` tells a partial
  view), or its box was joined from parts before. Two anchors of whole views are the matching
  function's to tell apart, not this rule's;
- **no end lies across them**: a box as wide as the class's short side and clearly shorter than
  its long side shows the object's end, its long side running away from the camera
  (:func:`~.object_centre.long_axis_shown`); two such ends side by side are two objects' ends, whatever
  box they make together (:func:`an_end_lies_across`);
- **they were never seen at one time**: two anchors seen in one frame are two percepts, two
  objects (every anchor keeps the symbols of anchors of its class seen in a frame with it,
  ``Anchor.seen_with``);
- both are trusted (confirmed, or missing after that), nothing is expected of either (an
  action's expectation or a search decides those), and their colours do not show two objects: a
  part beside a whole one shows no colour the whole one lacks (it shows only some of the object's
  faces, so its colours come in other shares: :func:`colours_tell_apart`), two parts do not differ.

The older symbol stays, as in every merge, and its box becomes the box around both: the object's
extent as far as the parts show it, which later views of parts beyond it widen, within the whole
one's extent (``Anchor.parts_fit``). The appearance views of a part (of all but a whole one) are
dropped: the partial-view tests let a part's views into its gallery when nothing showed them cut
(the bicycle's far end, 0.46 m of 1.6, seen whole five times), and a gallery of parts is evidence
against the object itself: in the run above, the joined anchor's part views scored under the
threshold against the bicycle's whole views, so a search did not take it. Without them the
object is compared by class, place and time until whole views come.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.anchoring.anchor import Anchor, AnchorState, turned_extent
from merlin2_sailor.anchoring.anchor_index import AnchorIndex
from merlin2_sailor.anchoring.colour_evidence import (
    ColourEvidenceConfig,
    anchor_colours_differ,
    part_shows_a_colour_the_whole_lacks,
)
from merlin2_sailor.anchoring.features import SMALL_OBJECT_EXTENT
from merlin2_sailor.anchoring.object_centre import long_axis_shown
from merlin2_sailor.anchoring.partial_view import EXTENT_CORROBORATING_VIEWS, PARTIAL_FOOTPRINT_SHARE, spans_known_whole


@dataclass(frozen=True, slots=True, eq=False)
class Parts:
    """``part`` (younger) and ``kept`` are parts of one object: ``kept`` takes ``part``'s views, and
    its box becomes the box from ``low`` to ``high`` (world frame, m) around both; ``known`` is the
    extent (:func:`~.anchor.turned_extent`) of the whole one of the class that the box fits in, and
    ``fit`` that extent with the slack, the most the parts may fill."""

    kept: Anchor
    part: Anchor
    low: np.ndarray
    high: np.ndarray
    known: np.ndarray
    fit: np.ndarray

    @property
    def reason(self) -> str:
        long_side, short_side, height = self.known
        return (f"parts of one {self.kept.class_name}: together they fit within one seen whole "
                f"({long_side:.2f} x {short_side:.2f} x {height:.2f} m) and were never seen at one time")


def note_seen_together(anchors: Iterable[Anchor], index: AnchorIndex) -> None:
    """Record, on each of ``anchors`` (those seen in one frame), the others of its class among them:
    they are two objects. Symbols no longer anchored are dropped on the way, so the record stays as
    small as the class's anchors."""
    by_class: dict[str, list[Anchor]] = {}
    for anchor in anchors:
        by_class.setdefault(anchor.class_name, []).append(anchor)
    for together in by_class.values():
        if len(together) < 2:
            continue
        symbols = {anchor.symbol for anchor in together}
        for anchor in together:
            anchor.seen_with = {symbol for symbol in anchor.seen_with | symbols
                                if symbol != anchor.symbol and symbol in index}


def seen_whole_at_last(anchor: Anchor, size: np.ndarray, whole: bool, known: np.ndarray | None) -> bool:
    """Make an anchor joined from parts an anchor of a whole object, where it just took a whole view
    (``whole``) whose box of ``size`` spans the class's ``known`` whole extent
    (:func:`.partial_view.spans_known_whole`); return whether it did.

    Its box, look and colour stop being its parts' from then on: a joined anchor's look is never
    compared (its views were of parts, :mod:`.anchor_comparison`) and its colour is no evidence
    (:mod:`.colour_evidence`), and without this it stays so for good, whatever it is seen as later.
    Measured: the living room's bicycle, seen end-on in two parts and joined, was then seen whole
    from its side six times (boxes 1.62-1.70 m long, uncut), its look and colour taken; a search for
    the wheeled bicycle, of another look, still scored it 1.00 by class, place and time alone,
    above the wheeled bicycle's own anchor (0.73, its look compared), and said it could not tell
    the two apart (`bicycle_wheeled_beside_another`, network, seed 0, 8 December 2026)."""
    if anchor.parts_fit is None or not whole or anchor.state is not AnchorState.CONFIRMED:
        return False
    if not spans_known_whole(size, known):
        return False
    anchor.parts_fit = None
    return True


def largest_seen_whole(index: AnchorIndex, class_name: str, slack: float) -> np.ndarray | None:
    """The extent (:func:`~.anchor.turned_extent`; m) of the largest whole one of the class the robot
    has seen, if it is of a large object; else None. An anchor known from enough whole views counts
    by its box; one whose box was joined from parts, by the whole one its parts were fit in
    (``parts_fit``, less the ``slack``), never by its own box: a search that merges the joined anchor
    into the one it sought takes that box and forgets its own whole extent, and the class's extent
    must not be lost with it, nor widened by joins step by step."""
    known = None
    for anchor in index.of_class(class_name):
        if anchor.parts_fit is not None:
            extent = anchor.parts_fit / (1.0 + slack)
        elif anchor.whole_views >= EXTENT_CORROBORATING_VIEWS:
            extent = turned_extent(anchor.size)
        else:
            continue
        if extent[0] > SMALL_OBJECT_EXTENT and (known is None or extent[0] > known[0]):
            known = extent
    return known


def decide_parts(seen: Sequence[Anchor], index: AnchorIndex, slack: float,
                 colour: ColourEvidenceConfig) -> list[Parts]:
    """Decisions joining each trusted anchor ``seen`` this frame with one other anchor of its class
    that is another part of its object (``slack``: the share by which the box around both may exceed
    the whole one's extent; 0 turns the rule off). At most one per anchor
    and frame: the next frame judges the grown box again."""
    if slack <= 0.0:
        return []
    decisions: list[Parts] = []
    settled: set[str] = set()
    known_of_class: dict[str, np.ndarray | None] = {}  # nothing changes until the decisions are applied
    for anchor in seen:
        if anchor.symbol in settled or not _trusted(anchor):
            continue
        if anchor.class_name not in known_of_class:
            known_of_class[anchor.class_name] = largest_seen_whole(index, anchor.class_name, slack)
        known = known_of_class[anchor.class_name]
        if known is None:
            continue
        fit = known * (1.0 + slack)
        slots = index.within(anchor.position.reshape(1, 3), float(fit[0]))[0]
        others = sorted((other for other in index.anchors_at(slots) if other.symbol not in settled
                         and _may_be_parts(anchor, other)), key=lambda other: other.first_seen)
        for other in others:
            fits = bool(np.all(extent_of_both(anchor, other) <= fit))
            if not fits or not (is_part(anchor, known) or is_part(other, known)):
                continue
            if an_end_lies_across(anchor, other, known):
                continue
            if colours_tell_apart(anchor, other, known, colour):
                continue
            kept, part = (anchor, other) if anchor.first_seen <= other.first_seen else (other, anchor)
            decisions.append(Parts(kept, part, *box_around(anchor, other), known, fit))
            settled.update((anchor.symbol, other.symbol))
            break
    return decisions


def extent_of_both(anchor: Anchor, other: Anchor) -> np.ndarray:
    """The extent (:func:`~.anchor.turned_extent`; m) of one object that both boxes would be parts of.

    Along the longer side of the box around both, and up, it is that box: parts of one object
    lie along it, each showing the object as far as it reaches. Across it, the box around both
    overstates the object when the two boxes are shifted sideways, as views from different sides
    and the error of a box shift them: a part's box is centred on the surface the camera saw, so
    the near end of a bicycle seen from one side and its far end seen from the other stand up to a
    box's width apart across it (0.19 m in `large_object_wheeled_away`, seed 2, 7 December 2026),
    and the depth band that makes a box takes in what stands just before the object (a bicycle's
    part, 0.15 m wide, reached 0.125 m past the bicycle's side towards the camera, its centre 0.05 m
    beyond the whole bicycle's box: `moved_to_the_far_room`, seed 0; over the 60 runs of the suite
    that day, a large object's box reached past the object across its thin side by 0.03 m at the
    median, 0.08 m at the 95th percentile, 0.115 m at the 99th). Where the two boxes share some of
    their width, the object is taken as wide as the wider box: two solid objects side by side share
    none of it but for that error, and what keeps two such objects apart is the rest of the rule
    (objects standing together are seen at one time; one of the two must be a part; their colours
    must agree). Boxes clear of each other across are two widths.
    """
    low, high = box_around(anchor, other)
    span = high - low
    along, across = _along_and_across(span)
    width = span[across]
    if _share_width(anchor, other, across):
        width = max(float(anchor.size[across]), float(other.size[across]))
    return np.array([span[along], width, span[2]])


def an_end_lies_across(anchor: Anchor, other: Anchor, known: np.ndarray) -> bool:
    """Whether either anchor's box shows its object's end (:func:`~.object_centre.long_axis_shown`: as
    wide as the class's short side, its long side running away from it) while the box around both
    runs across that: two ends side by side are the ends of two objects, not two parts of one lying
    the other way. Two bicycles 0.65 m apart, each seen only end-on and never at one time, made a box
    1.0 x 0.26 m, which fits a bicycle lying across them, and were joined (scenario suite,
    `bicycle_wheeled_beside_another`, network, seed 0, 7 December 2026)."""
    low, high = box_around(anchor, other)
    along, _ = _along_and_across(high - low)
    return any(axis is not None and axis != along
               for axis in (long_axis_shown(anchor.size, known), long_axis_shown(other.size, known)))


def reaches_past(whole: Anchor, part: Anchor) -> bool:
    """Whether the part shows its object reaching beyond the whole one's box, so that the object's
    box must grow: its centre beyond that box along the object, or its box clear of it across. A
    part's box that shares the whole one's width and sticks out across it is the error of a box
    (:func:`extent_of_both`), and must not widen the object."""
    low, high = box_around(whole, part)
    along, across = _along_and_across(high - low)
    beyond_along = abs(float(part.position[along] - whole.position[along])) > float(whole.size[along]) / 2.0
    return beyond_along or not _share_width(whole, part, across)


def box_around(anchor: Anchor, other: Anchor) -> tuple[np.ndarray, np.ndarray]:
    """The (low, high) corners (world frame, m) of the box around both anchors' boxes."""
    low = np.minimum(anchor.position - anchor.size / 2.0, other.position - other.size / 2.0)
    high = np.maximum(anchor.position + anchor.size / 2.0, other.position + other.size / 2.0)
    return low, high


def _along_and_across(span: np.ndarray) -> tuple[int, int]:
    """The floor axes (0 x, 1 y) along the longer and the shorter side of a box of this ``span``."""
    return (0, 1) if span[0] >= span[1] else (1, 0)


def _share_width(anchor: Anchor, other: Anchor, axis: int) -> bool:
    gap = abs(float(anchor.position[axis] - other.position[axis]))
    return gap < (float(anchor.size[axis]) + float(other.size[axis])) / 2.0


def is_part(anchor: Anchor, known: np.ndarray) -> bool:
    """Whether the anchor stands for a part of an object: its footprint clearly less than the whole
    one's ``known`` extent (as :mod:`.partial_view` tells a part), or its box joined from parts (it
    is as much of the object as its parts showed, and its views are theirs)."""
    return anchor.parts_fit is not None or turned_extent(anchor.size)[0] < PARTIAL_FOOTPRINT_SHARE * known[0]


def _trusted(anchor: Anchor) -> bool:
    return anchor.state in (AnchorState.CONFIRMED, AnchorState.MISSING) and anchor.expectation is None


def colours_tell_apart(anchor: Anchor, other: Anchor, known: np.ndarray, colour: ColourEvidenceConfig) -> bool:
    """Whether the two anchors' colours show two objects. A part beside a whole one is held to
    showing no colour the whole one lacks (:func:`~.colour_evidence.part_shows_a_colour_the_whole_lacks`):
    its colours come in other shares, as the faces it shows do. Two parts, or two anchors seen
    whole, are held to each other as any two anchors are."""
    anchor_is_part, other_is_part = is_part(anchor, known), is_part(other, known)
    if anchor_is_part != other_is_part:
        part, whole = (anchor, other) if anchor_is_part else (other, anchor)
        return part_shows_a_colour_the_whole_lacks(part, whole, colour)
    return anchor_colours_differ(anchor, other, colour)


def _may_be_parts(anchor: Anchor, other: Anchor) -> bool:
    return (
        other is not anchor
        and other.class_name == anchor.class_name
        and _trusted(other)
        and other.symbol not in anchor.seen_with
        and anchor.symbol not in other.seen_with
    )
