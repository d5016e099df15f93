"""Every merge the anchoring layer made is judged: one object's anchor forgotten into another's is wrong,
whatever the mission claims."""

from __future__ import annotations

from dataclasses import asdict

import pytest

from merlin2_sailor_demos.report.merges import MergeLog, MergeRecord
from merlin2_sailor_demos.report.scorecard import AnchorRecord, TrueObject
from merlin2_sailor_demos.report.truth_timeline import TruthTimeline
from merlin2_sailor_demos.report.verdict import judge

from .test_verdict import scorecard


def house(bicycle_at: tuple[float, float, float]) -> tuple[TrueObject, ...]:
    """Two bicycles 1.6 m long along y, and a book; the hall's bicycle at ``bicycle_at``."""
    return (TrueObject("bicycle", "bicycle", bicycle_at, (0.35, 1.6, 1.0)),
            TrueObject("living_bicycle", "bicycle", (2.6, 6.6, 0.5), (0.35, 1.6, 1.0)),
            TrueObject("book", "book", (1.0, 1.0, 0.8), (0.15, 0.22, 0.04)))


@pytest.fixture
def timeline() -> TruthTimeline:
    """The hall's bicycle wheeled in 0.65 m beside the living room's at 30 s."""
    line = TruthTimeline()
    line.record(0.0, house((5.6, 7.2, 0.5)))
    line.record(30.0, house((3.25, 6.6, 0.5)))
    return line


def anchor(symbol: str, at: tuple[float, float, float], class_name: str = "bicycle") -> AnchorRecord:
    return AnchorRecord(symbol, class_name, at, "missing")


def merged(timeline: TruthTimeline, *views: tuple[AnchorRecord, float], reason: str = "") -> MergeRecord:
    """bicycle_2 merged into bicycle_1 (the hall's bicycle's anchor, seen at 20 s) after ``views``."""
    log = MergeLog()
    log.note_view(anchor("bicycle_1", (5.62, 7.15, 0.5)), 20.0)
    for record, seen in views:
        log.note_view(record, seen)
    log.note_forgotten("bicycle_2", "bicycle_1", 50.0, reason)
    [merge] = log.judged(timeline)
    return merge


@pytest.mark.parametrize(("first_seen_at", "seen", "first_object"), [
    ((2.55, 5.85, 0.5), 25.0, "living_bicycle"),  # its near end, 0.75 m from its centre, before the move
    ((2.65, 6.7, 0.5), 45.0, "living_bicycle"),  # after the move, beside the wheeled one
    ((3.3, 6.5, 0.5), 45.0, "bicycle"),  # the wheeled bicycle's new anchor
    ((3.23, 5.95, 0.5), 45.0, "bicycle"),  # ... on its near end: nearer its footprint than the other's
    ((4.4, 6.9, 0.5), 45.0, None),  # more than 0.5 m from any bicycle: not judged
])
def test_a_merge_is_wrong_when_the_two_anchors_were_first_of_two_objects(timeline, first_seen_at, seen, first_object):
    merge = merged(timeline, (anchor("bicycle_2", first_seen_at), seen), reason="seen only while bicycle_1 was away")
    assert (merge.forgotten_refers, merge.into_refers) == (first_object, "bicycle")
    assert merge.wrong is (first_object == "living_bicycle")
    if merge.wrong:
        assert merge.problem() == ("bicycle_2 (the living_bicycle's) was merged into bicycle_1 (the bicycle's): "
                                   "seen only while bicycle_1 was away")


def test_an_anchor_that_took_another_objects_views_before_the_merge_is_judged_by_its_first(timeline):
    """The living room's bicycle's anchor, pulled onto the wheeled one by its views, then merged
    into the wheeled one's symbol: the living room's bicycle lost its symbol."""
    merge = merged(timeline, (anchor("bicycle_2", (2.55, 5.85, 0.5)), 25.0),
                   (anchor("bicycle_2", (3.2, 6.3, 0.5)), 46.0))
    assert merge.wrong and merge.forgotten_refers == "living_bicycle"


def test_a_view_is_judged_against_the_truth_of_its_time_even_when_the_truth_is_read_later():
    """The demo reads the ground truth once a second; the merges are judged at the end."""
    line = TruthTimeline()
    line.record(0.0, house((5.6, 7.2, 0.5)))
    log = MergeLog()
    log.note_view(anchor("bicycle_1", (5.62, 7.15, 0.5)), 20.0)
    log.note_view(anchor("bicycle_2", (3.3, 6.5, 0.5)), 30.5)  # the wheeled bicycle, 0.5 s after the move
    log.note_forgotten("bicycle_2", "bicycle_1", 31.0, "")
    line.record(30.0, house((3.25, 6.6, 0.5)))  # read after the view
    [merge] = log.judged(line)
    assert (merge.forgotten_refers, merge.wrong) == ("bicycle", False)


def test_an_anchor_never_shown_is_not_judged(timeline):
    log = MergeLog()
    log.note_forgotten("cup_9", "cup_1", 10.0, "")
    assert log.judged(timeline) == [MergeRecord(10.0, "cup_9", "cup_1", None, None, "")]
    assert not log.judged(timeline)[0].wrong


def test_a_wrong_merge_makes_the_run_wrong_whatever_the_mission_claimed(timeline):
    log = MergeLog()
    log.note_view(anchor("book_1", (1.0, 1.05, 0.8), "book"), 10.0)
    log.note_view(anchor("book_2", (1.1, 1.0, 0.8), "book"), 12.0)
    log.note_forgotten("book_2", "book_1", 12.5, "")  # two views of one book: right
    assert judge(scorecard(merges=[asdict(merge) for merge in log.judged(timeline)])).right
    log.note_view(anchor("bicycle_1", (5.62, 7.15, 0.5)), 20.0)
    log.note_view(anchor("bicycle_2", (2.55, 6.5, 0.5)), 25.0)
    log.note_forgotten("bicycle_2", "bicycle_1", 50.0, "a second anchor of its object")
    verdict = judge(scorecard(merges=[asdict(merge) for merge in log.judged(timeline)]))
    assert verdict.outcome == "found as cup_1" and not verdict.right
    assert verdict.problems == ("bicycle_2 (the living_bicycle's) was merged into bicycle_1 (the bicycle's): "
                                "a second anchor of its object",)


def test_a_scorecard_without_merges_is_judged_as_before_and_a_malformed_one_is_refused():
    assert judge(scorecard()).right
    with pytest.raises(ValueError, match="no usable 'claims' section"):
        judge(scorecard(merges=[{"forgotten": "cup_2"}]))


def test_a_box_across_two_objects_of_its_class_is_no_one_objects_anchor():
    """A shelf's books 0.3 m apart; a detector's box 0.68 m wide across two of them, anchored, is
    forgotten into one's anchor as not an object of its own: no object's symbol went to another's.
    The same anchor with a book's box is that book's, and its merge into its neighbour's is wrong."""
    shelf = tuple(TrueObject(f"book_{n}", "book", (1.7 + 0.3 * n, 7.8, 1.13), (0.2, 0.05, 0.26)) for n in range(4))
    line = TruthTimeline()
    line.record(0.0, shelf)

    def judged(size: tuple[float, float, float]) -> MergeRecord:
        log = MergeLog()
        log.note_view(anchor("book_8", (2.30, 7.77, 1.13), "book"), 10.0, (0.22, 0.11, 0.26))
        log.note_view(anchor("book_11", (2.13, 7.76, 1.21), "book"), 11.0, size)
        log.note_forgotten("book_11", "book_8", 12.0, "a box across book_8 and book_7")
        [merge] = log.judged(line)
        return merge

    across = judged((0.68, 0.49, 0.74))
    assert (across.forgotten_refers, across.into_refers, across.wrong) == (None, "book_2", False)
    one_book = judged((0.22, 0.11, 0.26))
    assert (one_book.forgotten_refers, one_book.wrong) == ("book_1", True)
