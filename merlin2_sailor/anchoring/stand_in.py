"""A newcomer seen only while an older anchor was away, beside its place, was that anchor.

Why. When the robot's pose estimate jumps for a moment (a turn, a localiser correction), every
object in view is seen off its place by the error, by different amounts for different
distances, so :mod:`.frame_registration` cannot always take it out (two objects in view, 0.15 m
and 0.17 m off: fewer than it needs, and not one shift). The rules forgive such a view by place;
the learned matcher, which reads how many of its widths a view stands from an anchor, rejects it
as a neighbour: measured in `moved_and_moved_back` (network, seed 4, 4 December 2026), a cup and
a book seen 0.16-0.17 m off for half a second became `cup_7` and `book_7`, confirmed within three
frames (0.12 s), while `cup_4` and `book_2` went MISSING; when the pose came back, so did the old
anchors, and the new ones went MISSING beside them, two duplicates for the rest of the run.
Nothing else repairs that pair: the two never shared a space (a cup is narrower than the error),
and the reappearance rules merge a newcomer into an *older* missing anchor, not the other way.

What it decides. A MISSING anchor is a stand-in for an older anchor of its class (and is forgotten
as a :class:`~.same_space.Duplicate`, the older symbol kept, as the planner knows it) when all of
these hold:

- the older anchor was not seen from the newcomer's first sighting to its last, and has been seen
  since (each anchor remembers the stamps of its last 64 sightings,
  :data:`~.anchor.RECENT_SIGHTINGS`): the two were never seen at one time, so one object may have
  been both. Whether the older one went MISSING meanwhile does not matter: a short glitch may leave
  it CONFIRMED while the newcomer is confirmed in three frames (`removed`, network, seed 4: a mug
  seen 0.19 m off became a second anchor while its own never went missing);
- it stands within ``reach`` of the older one (horizontally, plus what the larger of the two
  objects' extents explains): where the object was, not across the room;
- and so did the older one at its last sighting before the newcomer's first (each anchor remembers
  where it stood after those sightings, :attr:`~.anchor.Anchor.recent_places`): a momentary pose
  error shows an object off a place it keeps, while an older anchor that was away because its object
  was carried, and came back beside the newcomer, had stood elsewhere when the newcomer was first
  seen, so the newcomer is the object that was there already. Measured in
  `bicycle_wheeled_beside_another` (network, seed 1, 7 December 2026): the living room's bicycle,
  seen from the doorway 3 m from the hall's, was forgotten as the hall's bicycle's stand-in when the
  hall's one was found wheeled in beside it 40 s later;
- their colours do not differ, and a matcher that reads appearance takes it for the older one
  with place left out (:func:`~.anchor_comparison.score_anywhere`; a view off its place is
  judged by its look, as a search judges a found object);
- exactly one older anchor fits: two that were both away (look-alikes side by side) leave it
  undecided, and it stays.

A look-alike put beside an object while it is away, and taken away as it comes back, would fit
too; a scene that stages that is not told apart by anything the camera sees.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from merlin2_sailor.anchoring.anchor import Anchor, AnchorState
from merlin2_sailor.anchoring.anchor_comparison import score_anywhere
from merlin2_sailor.anchoring.anchor_index import AnchorIndex
from merlin2_sailor.anchoring.colour_evidence import ColourEvidenceConfig, anchor_colours_differ
from merlin2_sailor.anchoring.features import extent_slack
from merlin2_sailor.anchoring.matcher import Matcher
from merlin2_sailor.anchoring.same_space import Duplicate


def decide_stand_ins(
    went_missing: Iterable[Anchor], came_back: Iterable[Anchor], index: AnchorIndex, reach: float,
    colour: ColourEvidenceConfig, matcher: Matcher, match_threshold: float,
) -> list[Duplicate]:
    """Stand-ins among the anchors that ``went_missing`` this frame, and among the MISSING anchors
    beside those that ``came_back`` this frame (confirmed again after being missing); 0 ``reach``
    turns the rule off."""
    if reach <= 0.0:
        return []
    in_question = {anchor.symbol: anchor for anchor in went_missing if anchor.state is AnchorState.MISSING}
    for anchor in came_back:
        in_question.update((other.symbol, other) for other in _beside(anchor, index, reach)
                           if other.state is AnchorState.MISSING)
    decisions: list[Duplicate] = []
    for symbol in sorted(in_question):
        stand_in = in_question[symbol]
        if stand_in.expectation is not None:
            continue
        originals = [older for older in _beside(stand_in, index, reach)
                     if _was_away_all_its_life(older, stand_in) and _stood_beside_it_before(older, stand_in, reach)
                     and not anchor_colours_differ(older, stand_in, colour)]
        if len(originals) != 1:
            continue
        original = originals[0]
        score = score_anywhere(matcher, stand_in, original) if matcher.uses_appearance else None
        if score is not None and score < match_threshold:
            continue
        distance = float(np.linalg.norm(stand_in.position[:2] - original.position[:2]))
        decisions.append(Duplicate(original, stand_in, 0.0,
                                   f"seen only while {original.symbol} was away, {distance:.2f} m from it", score))
    return decisions


def _was_away_all_its_life(older: Anchor, stand_in: Anchor) -> bool:
    """Whether ``older`` (confirmed, nothing expected of it, of the stand-in's class and born
    before it) was not seen from the stand-in's first sighting to its last, and was seen since."""
    if (older.state is not AnchorState.CONFIRMED or older.expectation is not None
            or older.class_name != stand_in.class_name or older.first_seen >= stand_in.first_seen):
        return False
    sightings = np.asarray(older.recent_sightings, dtype=np.float64)
    if len(sightings) == 0 or (sightings[0] > stand_in.first_seen and len(sightings) < older.times_seen):
        return False  # its sightings then are no longer remembered: nothing says it was away
    during = (sightings >= stand_in.first_seen) & (sightings <= stand_in.last_seen)
    return not during.any() and bool((sightings > stand_in.last_seen).any())


def _stood_beside_it_before(older: Anchor, stand_in: Anchor, reach: float) -> bool:
    """Whether ``older`` stood within ``reach`` of the stand-in (on the floor, plus what the larger
    extent explains, as :func:`_beside` measures) at its latest remembered sighting before the
    stand-in's first; False when no such sighting is remembered with its place."""
    latest_first = zip(reversed(older.recent_sightings), reversed(older.recent_places), strict=False)
    place = next((place for stamp, place in latest_first if stamp < stand_in.first_seen), None)
    if place is None:
        return False
    slack = float(max(extent_slack(np.asarray(older.size)), extent_slack(np.asarray(stand_in.size))))
    return float(np.linalg.norm(np.asarray(place) - stand_in.position[:2])) - slack <= reach


def _beside(anchor: Anchor, index: AnchorIndex, reach: float) -> list[Anchor]:
    """Other anchors of its class whose centre is within ``reach`` of its own on the floor, plus
    what the larger of the two extents explains."""
    return [other for other in index.near(anchor, reach, horizontal=True) if other.class_name == anchor.class_name]
