"""Acquire and reacquire: one percept becomes a new anchor, or is fused into the one it matched.

These are the paper's two outcomes of matching, plus what perception says about an action's
expectation on the anchor it reacquires (perception outranks expectation: seen near the expected
place confirms it, seen elsewhere retracts it). The coordinator decides *which* happens; these
functions say what each does to the anchor and which events it makes.
"""

from __future__ import annotations

import numpy as np

from merlin2_sailor.anchoring.anchor import Anchor, AnchorState
from merlin2_sailor.anchoring.events import AnchorEventKind
from merlin2_sailor.anchoring.expectation import ExpectationKind
from merlin2_sailor.anchoring.frame_changes import FrameChanges
from merlin2_sailor.anchoring.fusion import FusionConfig
from merlin2_sailor.anchoring.lifecycle import LifecycleConfig, after_sighting, before_sighting, sighting_brings_back
from merlin2_sailor.anchoring.partial_view import smaller_than_known
from merlin2_sailor.anchoring.percept_checks import box_text, position_text
from merlin2_sailor.contract.percept import Percept
from merlin2_sailor.knowledge.model import Provenance


def acquire(
    symbol: str, percept: Percept, changes: FrameChanges, fusion: FusionConfig, lifecycle: LifecycleConfig,
    partial: bool = False, nearest: str = "",
) -> Anchor:
    """A new anchor named ``symbol`` from one percept (the caller indexes it); ``nearest``: the
    anchor of its class it came nearest to being, and why not, for the event (empty: none)."""
    anchor = Anchor.from_percept(symbol, percept, percept.embedding, fusion, partial)
    became_confirmed = after_sighting(anchor, lifecycle)
    changes.acquired.append(anchor)
    details = {"nearest_anchor": nearest} if nearest else {}
    changes.event(AnchorEventKind.ACQUIRED, symbol, class_name=anchor.class_name, tracker_id=percept.tracker_id,
                  at=position_text(anchor.position), **details)
    if became_confirmed:
        changes.event(AnchorEventKind.CONFIRMED, symbol, reason="seen", times_seen=anchor.times_seen)
        changes.confirmed_newcomers.append(anchor)
    return anchor


def reacquire(
    anchor: Anchor, percept: Percept, changes: FrameChanges, fusion: FusionConfig, lifecycle: LifecycleConfig,
    expectation_tolerance: float, continued: bool, partial: bool = False, scored: str = "",
) -> None:
    """Fuse ``percept`` into ``anchor`` (the caller refreshes the index); ``scored``: why it took
    the view, for the event (:func:`~.match_explanation.matched_over`; empty: not said)."""
    # A search for a missing anchor ends only once the anchor is back (see after_sighting):
    # one false detection in the searched disc must not end the search.
    searching = anchor.expectation is not None and anchor.expectation.is_search
    if anchor.expectation is not None and not searching:
        resolve_expectation(anchor, percept, changes, expectation_tolerance)
    was_missing = anchor.state is AnchorState.MISSING
    missing_since = anchor.missing_since
    # Why a view went to this anchor is read from both boxes (a part's box is centred off its object).
    boxes = {"view": box_text(percept.position, percept.size),
             "anchor_box": box_text(anchor.position, anchor.size)} if scored else {}
    # Less of the object than its whole views showed: seen from its end, its near face, the rest
    # beyond it along the line of sight. Whole by the camera's tests, such a view is partial all
    # the same; cut by them (a door frame, the image's edge), it is a near face too where it is
    # seen end-on: a cut takes from the view's width, never from its depth.
    shows_less = smaller_than_known(percept, anchor)
    partial = partial or shows_less
    before_sighting(anchor, percept, lifecycle)
    # A MISSING anchor's sighting too few to bring it back is no evidence of what the object looks
    # like (it may be a false box, or a look-alike, in a searched disc): its colour and look join
    # the anchor only once it is back. Three false "dog" boxes around a book, each taken in a
    # searched disc by the kitchen dog's lost anchor and never bringing it back, gave it their
    # colour (the only whole views it had), and the moved dog, recorded as found by its look, was
    # then refused for another colour (`large_object_moved`, network, seed 2, 6 December 2026).
    returning = was_missing and sighting_brings_back(anchor, lifecycle)
    anchor.absorb(percept, percept.embedding, fusion, partial, evidence=not was_missing or returning)
    became_confirmed = after_sighting(anchor, lifecycle)
    if anchor.state is AnchorState.MISSING:
        anchor.missing_since = missing_since  # not back yet: still on the clock that forgets it
    else:
        anchor.indistinguishable_from = ()  # seen as itself: its identity is decided again
        anchor.look_pending = ()
        if searching:
            resolve_expectation(anchor, percept, changes, expectation_tolerance)
    changes.reacquired.append(anchor)
    changes.event(
        AnchorEventKind.REACQUIRED, anchor.symbol, was_missing=was_missing, tracker_id=percept.tracker_id,
        tracker_continued=continued, **({"scored": scored} if scored else {}), **boxes,
    )
    if became_confirmed:
        changes.event(AnchorEventKind.CONFIRMED, anchor.symbol, reason="seen", times_seen=anchor.times_seen)
        if not was_missing:
            changes.confirmed_newcomers.append(anchor)
        else:
            changes.returned.append(anchor)


def resolve_expectation(anchor: Anchor, percept: Percept, changes: FrameChanges, tolerance: float) -> None:
    """Perception outranks expectation: seen near the expected place confirms, elsewhere retracts.
    A large object's view is centred on the object already, not on its near face
    (:mod:`.object_centre`)."""
    expectation = anchor.expectation
    assert expectation is not None
    distance = float(np.linalg.norm(np.asarray(percept.position) - anchor.position))
    details = {"expectation": expectation.describe(), "distance": distance}
    if distance > tolerance + expectation.radius:
        changes.event(AnchorEventKind.RETRACTED, anchor.symbol, reason="seen elsewhere", **details)
        drop_expectation(anchor)
        anchor.position = anchor.perceived_position.copy()
        return
    if not anchor.expectation_confirmed:
        changes.event(AnchorEventKind.CONFIRMED, anchor.symbol, reason="expectation", **details)
    if expectation.is_search and np.allclose(anchor.position, expectation.position):
        # Found by a search: where it was seen, not the middle of the searched disc, which partial
        # views (a bicycle seen through a door frame) do not move it from. Left there, the bicycle
        # found from the kitchen was placed 2.1 m off, in the kitchen (scenario suite,
        # `large_object_wheeled_away`, network, 6 December 2026).
        anchor.position = np.asarray(percept.position, dtype=np.float64).copy()
        anchor.perceived_position = anchor.position.copy()
    if expectation.kind is ExpectationKind.CARRIED:
        anchor.expectation_confirmed = True  # still carried: keep following the robot
    else:
        drop_expectation(anchor)


def drop_expectation(anchor: Anchor) -> None:
    """The anchor's position is perception's again."""
    anchor.expectation = None
    anchor.expectation_confirmed = False
    anchor.provenance = Provenance.PERCEIVED
