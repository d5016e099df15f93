"""An anchor pulled off its place by a look-alike goes back when its own object shows up there.

Seen again after a while, an anchor trusts a lone percept of its class near it enough to jump to
it (the object may have been moved while unseen: :func:`.fusion.fuse_position` lets the position
follow). When that percept was a look-alike put down beside the object, and the detector missed
the object itself in that first frame, the object is seen on its old spot a frame later, matches
no anchor (its own has just left) and is acquired anew: the look-alike keeps the old symbol and
the planner is sent to it. Measured on the `lookalike_added` scenario (3 December 2026): a blue
mug put 0.26 m from the hall's blue mug while the robot drove away took its symbol in 2 of 3
runs with the rules, each time by such a jump (the anchor moved 0.20 m in one sighting; its
object was acquired anew on the old spot in the next frame).

The first frame cannot tell the two stories apart; the next ones can. A sighting that moves an
anchor at least half of ``place_jump`` records the place it left (:func:`note_jump`; a shorter
absence gives a smaller step, which the next sightings may carry on). A newcomer of its class
acquired within ``place_review`` seconds of it, within half a jump of the place left and more
than a jump from where the anchor is now, with colours not differing, is the anchor's
object that never moved: one change (a look-alike added) explains what was seen, where the jump
would need two (the object moved and a look-alike put in its place). The two anchors trade
places (:class:`Return`): the old symbol is back on its object, the newer one on the look-alike.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.anchoring.anchor import Anchor, AnchorState
from merlin2_sailor.anchoring.anchor_index import AnchorIndex
from merlin2_sailor.anchoring.colour_evidence import ColourEvidenceConfig, anchor_colours_differ


@dataclass(frozen=True, slots=True, eq=False)
class Return:
    """``anchor`` jumped to another object; ``newcomer`` was acquired on the place it left."""

    anchor: Anchor
    newcomer: Anchor
    jump: float
    """How far (m) the anchor had gone from the place it left."""


def note_jump(anchor: Anchor, before: np.ndarray, stamp: float, place_jump: float, place_review: float) -> None:
    """Record the place ``anchor`` left if the sighting at ``stamp`` moved it half of ``place_jump``
    or more from ``before`` (its position before the sighting). The first place left stays for the
    review period (the steps that follow keep pointing home); after it, the record is dropped."""
    if place_jump <= 0.0:
        return
    reviewing = anchor.left_place is not None and stamp - anchor.left_at <= place_review
    if reviewing:
        return
    if float(np.linalg.norm(anchor.position - before)) >= place_jump / 2.0:
        anchor.left_place = np.array(before, dtype=np.float64)
        anchor.left_at = stamp
    else:
        anchor.left_place = None


def decide_returns(
    acquired: Iterable[Anchor], index: AnchorIndex, stamp: float, place_jump: float, place_review: float,
    colour: ColourEvidenceConfig,
) -> list[Return]:
    """Returns for the anchors ``acquired`` this frame (0 ``place_jump`` turns the rule off); each
    anchor and each newcomer is in one at most, the nearest newcomer to the place left first."""
    if place_jump <= 0.0:
        return []
    pairs: list[tuple[float, Anchor, Anchor]] = []
    for newcomer in acquired:
        if newcomer.symbol not in index:
            continue
        for anchor in index.of_class(newcomer.class_name):
            if _returns(anchor, newcomer, stamp, place_jump, place_review, colour):
                distance = float(np.linalg.norm(newcomer.position - anchor.left_place))
                pairs.append((distance, anchor, newcomer))
    decisions: list[Return] = []
    taken: set[str] = set()
    for _, anchor, newcomer in sorted(pairs, key=lambda pair: (pair[0], pair[1].symbol, pair[2].symbol)):
        if anchor.symbol in taken or newcomer.symbol in taken:
            continue
        taken.update((anchor.symbol, newcomer.symbol))
        decisions.append(Return(anchor, newcomer, float(np.linalg.norm(anchor.position - anchor.left_place))))
    return decisions


def _returns(
    anchor: Anchor, newcomer: Anchor, stamp: float, place_jump: float, place_review: float,
    colour: ColourEvidenceConfig,
) -> bool:
    """Whether ``newcomer`` stands where ``anchor`` was before a jump of the review period."""
    if anchor is newcomer or anchor.left_place is None or stamp - anchor.left_at > place_review:
        return False
    if anchor.state is not AnchorState.CONFIRMED or anchor.expectation is not None:
        return False  # a sought or expected anchor is the search's and the expectation's to settle
    if newcomer.first_seen < anchor.left_at:
        return False  # it was there before the jump: the jump was not away from it
    home = float(np.linalg.norm(newcomer.position - anchor.left_place))
    away = float(np.linalg.norm(newcomer.position - anchor.position))
    on_the_place_left = home <= place_jump / 2.0 and away > place_jump
    return on_the_place_left and not anchor_colours_differ(anchor, newcomer, colour)


def trade_places(decision: Return) -> None:
    """The anchor takes the newcomer's place (its object's), the newcomer the look-alike's."""
    anchor, newcomer = decision.anchor, decision.newcomer
    anchor.position, newcomer.position = newcomer.position.copy(), anchor.position.copy()
    anchor.position_variance, newcomer.position_variance = newcomer.position_variance, anchor.position_variance
    anchor.last_tracker_id, newcomer.last_tracker_id = newcomer.last_tracker_id, anchor.last_tracker_id
    anchor.perceived_position = anchor.position.copy()
    newcomer.perceived_position = newcomer.position.copy()
    anchor.left_place = None
