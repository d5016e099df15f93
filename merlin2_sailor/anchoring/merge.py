"""Carrying out identity repair's decisions (:mod:`.identity_repair`) on the anchors.

A merge keeps the older symbol, since that is the one the planner and the knowledge base know:
the kept anchor takes the merged one's views, sightings and class votes, and, when the object
was found elsewhere, its place. An undecided case changes no identity: each lost anchor records
what it cannot be told from, and an AMBIGUOUS event says so. A duplicate (:mod:`.same_space`) is
forgotten, its object keeping the other symbol. A jump undone (:mod:`.place_return`) trades the
two anchors' places, so each symbol is back on its own object. Parts of one object (:mod:`.parts`)
become one anchor, the older, whose box is the box around both.
"""

from __future__ import annotations

from merlin2_sailor.anchoring.anchor import Anchor, AnchorState
from merlin2_sailor.anchoring.anchor_index import AnchorIndex
from merlin2_sailor.anchoring.events import AnchorEventKind
from merlin2_sailor.anchoring.frame_changes import FrameChanges
from merlin2_sailor.anchoring.fusion import FusionConfig
from merlin2_sailor.anchoring.identity_repair import Decision, LookPending, Merge, Unconfirmed
from merlin2_sailor.anchoring.observation import drop_expectation
from merlin2_sailor.anchoring.partial_view import EXTENT_CORROBORATING_VIEWS
from merlin2_sailor.anchoring.parts import Parts, is_part, reaches_past
from merlin2_sailor.anchoring.percept_checks import box_text, position_text
from merlin2_sailor.anchoring.place_return import Return, trade_places
from merlin2_sailor.anchoring.same_space import Duplicate


def withdraw_stale_ambiguities(index: AnchorIndex) -> None:
    """An anchor stays one that cannot be told from others only while all of them are anchors: once
    one was merged or forgotten, the evidence has changed, and the next judgement decides afresh
    (and says so again if they still cannot be told apart). Left standing, a stale "cannot be told
    from cup_9, cup_12" after cup_12 proved a second anchor of cup_9's mug ended every later search
    for the red mug unsuccessful (test_mission_end_to_end, network, 5 December 2026)."""
    for anchor in index.missing():
        if any(symbol not in index for symbol in anchor.indistinguishable_from):
            anchor.indistinguishable_from = ()
        if anchor.found_by_look_alone and anchor.found_by_look_alone not in index:
            anchor.found_by_look_alone = ""
        anchor.look_pending = tuple(symbol for symbol in anchor.look_pending if symbol in index)


def join_parts(decision: Parts, index: AnchorIndex, changes: FrameChanges, fusion: FusionConfig) -> None:
    """Make two parts of one object one anchor: the older symbol, the views of both, and the box of
    the whole one where one of them is whole and the other does not reach past it
    (:func:`.parts.reaches_past`), else the box around both.

    A part whose centre lies beyond the whole one's box along the object shows that the object
    reaches farther than those views did: they were whole by the partial-view tests, not by the
    object (a footprint over ``PARTIAL_FOOTPRINT_SHARE`` of the whole one's is not a part, yet may
    miss a quarter of it). The wheeled bicycle's near end, seen from the hall without a cut, made an
    anchor 1.23 m long centred 0.5 m from the bicycle's middle, and six views of its far end were
    joined into it without moving it, so the found bicycle stood half a metre off (scenario suite,
    `large_object_wheeled_away`, network, seed 1, 6 December 2026). A part within the box is noise
    of it (a part's box reaches past the object by a few decimetres), and so is one sticking out
    across it while sharing its width (the depth band took in what stood before the object): the
    whole box stays.

    One of the two was seen in this frame, so the object is: the anchor is confirmed and visible.
    A part's appearance views are dropped (:mod:`.parts` says why). A box around parts holds later
    views as an extent seen whole does (:data:`.partial_view.EXTENT_CORROBORATING_VIEWS` whole views'
    worth): a later view of a part, even one no test saw cut, keeps the anchor alive without moving
    it (:func:`.partial_view.smaller_than_known`). Without that, views of the bicycle's far end that
    nothing showed cut pulled the joined anchor 0.6 m onto that end (scenario suite, 6 December 2026).
    It keeps the extent it was fit in (``parts_fit``): later views of parts beyond the box widen it
    within that, and it is never the extent that joins are judged by, so joins cannot widen the
    class's known extent step by step."""
    kept, part = decision.kept, decision.part
    boxes = _boxes(kept, part)
    whole = next((anchor for anchor in (kept, part) if not is_part(anchor, decision.known)), None)
    for anchor in (kept, part):
        if anchor is not whole:  # its views are of parts, not of the object (see parts)
            anchor.gallery = anchor.gallery_scales = None
    if whole is not None and reaches_past(whole, part if whole is kept else kept):
        box = ((decision.low + decision.high) / 2.0, decision.high - decision.low,
               max(whole.whole_views, EXTENT_CORROBORATING_VIEWS), decision.fit)
    elif whole is not None:
        box = (whole.position.copy(), whole.size.copy(), whole.whole_views, whole.parts_fit)
    else:
        box = ((decision.low + decision.high) / 2.0, decision.high - decision.low, EXTENT_CORROBORATING_VIEWS,
               decision.fit)
    kept.absorb_anchor(part, fusion, moved=False)
    _hand_over_sightings(kept, part, index)
    index.remove(part.symbol)
    part.visible = False
    part.state = AnchorState.FORGOTTEN
    kept.position, kept.size, kept.whole_views, kept.parts_fit = box
    kept.perceived_position = kept.position.copy()
    kept.visible = True
    was_missing = kept.state is AnchorState.MISSING
    kept.state = AnchorState.CONFIRMED
    kept.missing_since = kept.lost_after = kept.lost_at = None
    kept.missed_frames = kept.recovery_sightings = 0
    kept.indistinguishable_from = ()
    index.refresh(kept)
    changes.forgotten.append(part)
    if kept not in changes.reacquired:
        changes.reacquired.append(kept)
    changes.event(AnchorEventKind.FORGOTTEN, part.symbol, reason=f"{decision.reason}: it is {kept.symbol}",
                  into=kept.symbol, **boxes)
    changes.event(AnchorEventKind.CONFIRMED, kept.symbol, reason=decision.reason, merged=part.symbol,
                  was_missing=was_missing, at=position_text(kept.position))


def _boxes(kept: Anchor, forgotten: Anchor) -> dict[str, str]:
    """The two anchors' boxes before a merge, for the FORGOTTEN event: what the evidence looked like."""
    return {"box": box_text(forgotten.position, forgotten.size), "into_box": box_text(kept.position, kept.size)}


def _hand_over_sightings(kept: Anchor, merged: Anchor, index: AnchorIndex) -> None:
    """Anchors seen at one time with the merged anchor were seen with the kept one's object."""
    for anchor in index.of_class(merged.class_name):
        if merged.symbol in anchor.seen_with:
            anchor.seen_with.discard(merged.symbol)
            if anchor is not kept:
                anchor.seen_with.add(kept.symbol)


def apply_decision(
    decision: Decision | Duplicate | Return | None, index: AnchorIndex, changes: FrameChanges, fusion: FusionConfig
) -> None:
    """Carry out a merge, forget a duplicate, undo a jump, or report what could not be decided
    (parts of one object are joined before these are decided: :func:`join_parts`)."""
    if decision is None:
        return
    if isinstance(decision, Return):
        anchor, newcomer = decision.anchor, decision.newcomer
        trade_places(decision)
        index.refresh(anchor)
        index.refresh(newcomer)
        if anchor not in changes.reacquired:
            changes.reacquired.append(anchor)
        changes.event(AnchorEventKind.REACQUIRED, anchor.symbol, was_missing=False,
                      reason=f"seen again on the place it had left; its {decision.jump:.2f} m jump went to "
                             f"another object, now {newcomer.symbol}", at=position_text(anchor.position))
        return
    if isinstance(decision, Duplicate):
        duplicate = decision.duplicate
        _hand_over_sightings(decision.kept, duplicate, index)
        index.remove(duplicate.symbol)
        duplicate.visible = False
        duplicate.state = AnchorState.FORGOTTEN
        changes.forgotten.append(duplicate)
        evidence = {"overlap": round(decision.overlap, 2)}
        if decision.score is not None:
            evidence["score"] = round(decision.score, 3)
        changes.event(AnchorEventKind.FORGOTTEN, duplicate.symbol,
                      reason=decision.explanation, into=decision.kept.symbol, **evidence,
                      **_boxes(decision.kept, duplicate))
        return
    if isinstance(decision, Unconfirmed):
        # Nothing merged, nothing said yet: the search looks on (see identity_repair).
        decision.sought.found_by_look_alone = decision.found.symbol
        return
    if isinstance(decision, LookPending):
        # Nothing merged, nothing said yet: a closer view may tell them apart (see identity_repair).
        decision.sought.look_pending = tuple(dict.fromkeys(
            (*decision.sought.look_pending, *(candidate.symbol for candidate in decision.candidates))))
        return
    if not isinstance(decision, Merge):
        involved = [anchor.symbol for anchor in (*decision.lost, *decision.found)]
        for lost in decision.lost:
            others = tuple(symbol for symbol in involved if symbol != lost.symbol)
            lost.found_by_look_alone = ""  # another copy turned up: the look alone decides nothing
            if others == lost.indistinguishable_from:
                continue  # said already; a search re-decides each frame something new is confirmed
            lost.indistinguishable_from = others
            changes.event(AnchorEventKind.AMBIGUOUS, lost.symbol, reason=decision.reason,
                          candidates=",".join(lost.indistinguishable_from),
                          scores=",".join(f"{score:.2f}" for score in decision.scores))
        return
    kept, merged = decision.kept, decision.merged
    boxes = _boxes(kept, merged)
    still_missing = merged.state is AnchorState.MISSING
    was_visible = merged.visible
    kept.absorb_anchor(merged, fusion, decision.moved)
    _hand_over_sightings(kept, merged, index)
    index.remove(merged.symbol)
    merged.visible = False
    kept.visible = was_visible
    drop_expectation(kept)
    kept.indistinguishable_from = ()
    kept.found_by_look_alone = ""
    kept.look_pending = ()
    # A merged anchor that is missing leaves the kept one missing, on its clock: the object
    # was last seen under that symbol, and seeing it again confirms it as usual.
    kept.state = AnchorState.MISSING if still_missing else AnchorState.CONFIRMED
    kept.missing_since = merged.missing_since if still_missing else None
    kept.lost_after = merged.lost_after if still_missing else None
    kept.lost_at = merged.lost_at if still_missing else None
    kept.missed_frames = merged.missed_frames if still_missing else 0
    kept.recovery_sightings = merged.recovery_sightings if still_missing else 0
    kept.recovery_at = merged.recovery_at if still_missing else None
    merged.state = AnchorState.FORGOTTEN
    index.refresh(kept)
    changes.forgotten.append(merged)
    changes.reacquired.append(kept)
    changes.event(AnchorEventKind.FORGOTTEN, merged.symbol, reason=f"{decision.reason}: it is {kept.symbol}",
                  into=kept.symbol, score=round(decision.score, 3), **boxes)
    if not still_missing:
        changes.event(AnchorEventKind.CONFIRMED, kept.symbol, reason=decision.reason, merged=merged.symbol)
