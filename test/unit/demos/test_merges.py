"""Every merge the anchoring layer made is judged: one object's anchor forgotten into another's is wrong,
whatever the mission claims."""

from __future__ import annotations

import pytest

from merlin2_sailor_demos.report.merges import MergeLog, MergeRecord
from merlin2_sailor_demos.report.scorecard import AnchorRecord, TrueObject
from merlin2_sailor_demos.report.truth_timeline import TruthTimeline
from merlin2_sailor_demos.report.verdict import judge

from .test_verdict import scorecard


def house(bicycle_at: tuple[float, float, float]) -> tuple[TrueObject, ...]:
    """Two bicycles and a book; the hall's bicycle at ``bicycle_at``."""
    return (TrueObject("bicycle", "bicycle", bicycle_at), TrueObject("living_bicycle", "bicycle", (2.6, 6.6, 0.5)),
            TrueObject("book", "book", (1.0, 1.0, 0.8)))


@pytest.fixture
def timeline() -> TruthTimeline:
    """The hall's bicycle wheeled beside the living room's at 30 s."""
    line = TruthTimeline()
    line.record(0.0, house((5.6, 7.2, 0.5)))
    line.record(30.0, house((3.25, 6.6, 0.5)))
    return line


def anchor(symbol: str, at: tuple[float, float, float], class_name: str = "bicycle") -> AnchorRecord:
    return AnchorRecord(symbol, class_name, at, "missing")


@pytest.mark.parametrize(("forgotten_at", "seen", "wrong"), [
    ((2.55, 6.5, 0.5), 25.0, True),  # the living room's bicycle, before the move: another object
    ((2.65, 6.7, 0.5), 45.0, True),  # ... or after it, beside the wheeled one
    ((3.3, 6.5, 0.5), 45.0, False),  # the wheeled bicycle's new anchor: the same object
    ((4.4, 6.9, 0.5), 45.0, None),  # an anchor more than 0.5 m from any bicycle: not judged
])
def test_a_merge_is_wrong_when_the_two_anchors_referred_to_two_objects(timeline, forgotten_at, seen, wrong):
    log = MergeLog()
    log.note_view(anchor("bicycle_1", (5.62, 7.15, 0.5)), 20.0)  # the hall's, last seen before the move
    log.note_view(anchor("bicycle_2", forgotten_at), seen)
    log.note_forgotten("bicycle_2", "bicycle_1", 50.0, "seen only while bicycle_1 was away", timeline)
    [merge] = log.merges
    assert merge.into_refers == "bicycle"
    assert merge.wrong is bool(wrong)
    if wrong is None:
        assert merge.forgotten_refers is None
    elif wrong:
        assert merge.problem() == ("bicycle_2 (the living_bicycle) was merged into bicycle_1 (the bicycle): "
                                   "seen only while bicycle_1 was away")


def test_the_kept_anchor_seen_after_the_merge_is_never_blamed(timeline):
    """Should the anchors message after the merge arrive before its event, the kept anchor already
    stands where the merged one did: the merge is judged right, not wrongly blamed."""
    log = MergeLog()
    log.note_view(anchor("bicycle_1", (5.62, 7.15, 0.5)), 20.0)
    log.note_view(anchor("bicycle_5", (3.3, 6.5, 0.5)), 45.0)
    log.note_view(anchor("bicycle_1", (3.3, 6.5, 0.5)), 45.0)  # merged already
    log.note_forgotten("bicycle_5", "bicycle_1", 45.1, "", timeline)
    assert not log.merges[0].wrong


def test_an_anchor_never_shown_is_not_judged(timeline):
    log = MergeLog()
    log.note_forgotten("cup_9", "cup_1", 10.0, "", timeline)
    assert log.merges == [MergeRecord(10.0, "cup_9", "cup_1", None, None, "")]
    assert not log.merges[0].wrong


def test_a_wrong_merge_makes_the_run_wrong_whatever_the_mission_claimed(timeline):
    log = MergeLog()
    log.note_view(anchor("book_1", (1.0, 1.05, 0.8), "book"), 10.0)
    log.note_view(anchor("book_2", (1.1, 1.0, 0.8), "book"), 12.0)
    log.note_forgotten("book_2", "book_1", 12.5, "", timeline)  # two views of one book: right
    assert judge(scorecard(merges=log.as_dicts())).right
    log.note_view(anchor("bicycle_1", (5.62, 7.15, 0.5)), 20.0)
    log.note_view(anchor("bicycle_2", (2.55, 6.5, 0.5)), 25.0)
    log.note_forgotten("bicycle_2", "bicycle_1", 50.0, "a second anchor of its object", timeline)
    verdict = judge(scorecard(merges=log.as_dicts()))
    assert verdict.outcome == "found as cup_1" and not verdict.right
    assert verdict.problems == ("bicycle_2 (the living_bicycle) was merged into bicycle_1 (the bicycle): "
                                "a second anchor of its object",)


def test_a_scorecard_without_merges_is_judged_as_before_and_a_malformed_one_is_refused():
    assert judge(scorecard()).right
    with pytest.raises(ValueError, match="no usable 'claims' section"):
        judge(scorecard(merges=[{"forgotten": "cup_2"}]))
