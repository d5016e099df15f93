"""A mission's claim is judged against the ground truth: succeeding on the wrong object is wrong."""

from __future__ import annotations

import copy

import pytest

from merlin2_sailor_demos.report.scorecard import AnchorRecord, TrueObject
from merlin2_sailor_demos.report.truth_timeline import TruthTimeline, refers_to
from merlin2_sailor_demos.report.verdict import judge
from merlin2_sailor_demos.world.mission import Expectation, ExpectedOutcome


def scorecard(**claims) -> dict:
    """A scorecard as the mission demo writes it: the red mug was cup_1, the green mug cup_2."""
    base = {
        "target": "red_mug", "target_symbol": "cup_1", "target_present": True, "target_place": "living_room",
        "symbols_before": {"red_mug": "cup_1", "green_mug": "cup_2", "book": "book_1"},
        "refers_to": {"cup_1": "red_mug", "cup_2": "green_mug", "book_1": "book"},
        "last_seen": {"cup_1": 100.0, "cup_2": 50.0, "book_1": 40.0},
        "object_at": {"cup_1": ["living_room"], "cup_2": ["living_room"], "book_1": ["kitchen"]},
        "fetch": {"ran": True, "succeeded": True, "reason": "every goal holds"},
        "expect": {"outcome": "found"},
    }
    base.update(claims)
    return {"duplicates": [], "identity_switches": {"red_mug": 2}, "outcome": {"seconds": 95.4}, "claims": base}


def test_found_under_its_symbol_where_the_knowledge_base_says_is_right() -> None:
    verdict = judge(scorecard())
    assert verdict.right and verdict.outcome == "found as cup_1" and verdict.problems == ()
    assert (verdict.identity_switches, verdict.duplicates, verdict.seconds) == (2, 0, 95.4)


def test_a_mission_that_succeeds_on_the_wrong_object_is_wrong() -> None:
    # The search merged the green mug into the red mug's symbol, and the mission said "succeeded".
    verdict = judge(scorecard(refers_to={"cup_1": "green_mug", "cup_2": "green_mug", "book_1": "book"}))
    assert not verdict.right and verdict.outcome == "found as cup_1" and verdict.claimed == "green_mug"
    assert "claimed cup_1, which refers to green_mug, not the red_mug" in verdict.problems


def test_a_success_whose_symbol_refers_to_nothing_is_wrong() -> None:
    assert not judge(scorecard(refers_to={"cup_2": "green_mug"})).right


def test_the_knowledge_base_must_place_the_found_object_where_it_is() -> None:
    verdict = judge(scorecard(object_at={"cup_1": ["kitchen"]}))
    assert not verdict.right and "places cup_1 at kitchen; the red_mug is at living_room" in verdict.problems[0]


def test_an_object_in_the_house_not_found_is_wrong_but_not_a_false_claim() -> None:
    verdict = judge(scorecard(fetch={"ran": True, "succeeded": False, "reason": "cup_1 was not found at hall"},
                              object_at={}))
    assert not verdict.right and verdict.outcome == "not found"
    assert verdict.problems == ("not found, though the red_mug is in the house (cup_1 was not found at hall)",)


@pytest.mark.parametrize("allowed", [True, False])
def test_cannot_tell_apart_is_right_only_where_the_scenario_allows_it(allowed) -> None:
    card = scorecard(fetch={"ran": True, "succeeded": False, "reason": "cup_1 cannot be told from cup_5, cup_6"},
                     object_at={}, expect={"outcome": "found", "unknown_allowed": allowed})
    verdict = judge(card)
    assert verdict.outcome == "unknown" and verdict.right is allowed


def test_an_ambiguous_event_about_the_target_says_cannot_tell_apart_too() -> None:
    failed = {"ran": True, "succeeded": False, "reason": "gave up after 3 replan(s); last: find_object aborted"}
    event = {"symbol": "cup_1", "stamp": 12.0, "details": {"candidates": "cup_5,cup_6"}}
    assert judge(scorecard(fetch=failed, object_at={}, ambiguous=[event])).outcome == "unknown"
    other = {**event, "symbol": "book_1"}
    assert judge(scorecard(fetch=failed, object_at={}, ambiguous=[other])).outcome == "not found"


def test_cannot_tell_apart_after_giving_the_symbol_away_is_wrong() -> None:
    card = scorecard(fetch={"ran": True, "succeeded": False, "reason": "cannot tell them apart"},
                     refers_to={"cup_1": "green_mug", "cup_2": "green_mug"}, object_at={},
                     expect={"outcome": "found", "unknown_allowed": True})
    assert judge(card).problems[0] == "cup_1 was given to green_mug"


def removed(**claims) -> dict:
    return scorecard(target_present=False, target_place=None, expect={"outcome": "not_found"}, **claims)


def test_a_removed_object_not_found_and_placed_nowhere_is_right() -> None:
    verdict = judge(removed(fetch={"ran": True, "succeeded": False, "reason": "not found at any stop"},
                            object_at={"cup_2": ["living_room"]}))
    assert verdict.right and verdict.outcome == "not found"


def test_a_removed_object_reported_found_is_wrong_whatever_the_mission_says() -> None:
    verdict = judge(removed(refers_to={"cup_1": "green_mug", "cup_2": "green_mug"}))
    assert not verdict.right and verdict.outcome == "found as cup_1"
    assert verdict.problems[0] == "reported found as cup_1, but the red_mug was removed (cup_1 refers to green_mug)"


def test_a_removed_object_the_knowledge_base_still_places_is_wrong() -> None:
    verdict = judge(removed(fetch={"ran": True, "succeeded": False, "reason": "not found"}))
    assert not verdict.right and "places the removed red_mug: object_at(cup_1, living_room)" in verdict.problems[0]


def test_a_story_that_failed_before_the_find_is_wrong() -> None:
    verdict = judge(scorecard(fetch={"ran": False, "succeeded": False, "reason": "exploring failed"}))
    assert not verdict.right and verdict.outcome == "not run"


def test_symbols_kept_new_and_anchored_once() -> None:
    swapped = scorecard(refers_to={"cup_1": "red_mug", "cup_2": "green_mug", "cup_9": "green_mug", "book_1": "book"},
                        last_seen={"cup_1": 100.0, "cup_2": 50.0, "cup_9": 90.0})
    keep = Expectation(ExpectedOutcome.FOUND, keep_symbols=("green_mug",))
    assert judge(swapped, keep).problems == ("green_mug went from cup_2 to cup_9",)  # its newest anchor wins
    assert judge(scorecard(), keep).right
    new = Expectation(new_symbols=("green_mug",))
    assert judge(scorecard(), new).problems == ("green_mug took cup_2, the symbol of green_mug",)
    assert judge(scorecard(symbols_before={"red_mug": "cup_1"}), new).right
    once = Expectation(anchored_once=("green_mug", "book", "nothing"))
    assert judge(swapped, once).problems == ("green_mug has 2 anchors", "nothing has 0 anchors")


def test_the_expectation_defaults_to_the_one_the_scorecard_records() -> None:
    card = removed(fetch={"ran": True, "succeeded": False, "reason": "not found"}, object_at={})
    assert judge(card).right and not judge(card, Expectation()).right


def test_a_scorecard_without_claims_is_refused_clearly() -> None:
    with pytest.raises(ValueError, match="no usable 'claims' section"):
        judge({"duplicates": []})
    broken = copy.deepcopy(scorecard())
    del broken["claims"]["fetch"]
    with pytest.raises(ValueError, match="claims"):
        judge(broken)


def test_a_symbol_refers_to_what_its_anchor_last_saw_not_what_stands_there_now() -> None:
    red = TrueObject("red_mug", "cup", (2.0, 2.0, 0.8))
    green = TrueObject("green_mug", "cup", (1.6, 5.7, 0.5))
    timeline = TruthTimeline()
    timeline.record(10.0, [red, green])
    timeline.record(10.0, [red, green])  # the same truth again: one version
    swapped = [TrueObject("red_mug", "cup", green.position), TrueObject("green_mug", "cup", red.position)]
    timeline.record(60.0, swapped)
    assert len(timeline.versions) == 2
    stale = AnchorRecord("cup_2", "cup", (1.62, 5.68, 0.5), "confirmed")  # the green mug's, unseen since 40 s
    assert refers_to(stale, 40.0, timeline) == "green_mug"
    seen_again = AnchorRecord("cup_1", "cup", (2.01, 2.0, 0.8))  # the red mug's, seen at 80 s on the green mug
    assert refers_to(seen_again, 80.0, timeline) == "green_mug"
    assert refers_to(AnchorRecord("book_1", "book", (2.0, 2.0, 0.8)), 80.0, timeline) is None  # class counts
    assert refers_to(AnchorRecord("cup_7", "cup", (3.0, 3.0, 0.8)), 80.0, timeline) is None  # too far
    assert timeline.at(0.0) == (red, green)  # before the first version: the first


def test_each_duplicate_comes_with_where_it_came_from_and_an_old_scorecard_says_unknown() -> None:
    card = scorecard()
    card["duplicates"] = ["tv_2", "dog_3"]
    card["duplicate_origins"] = {"tv_2": "tv_2 (confirmed), anchored anew: tv_1 ruled out by colour"}
    verdict = judge(card)
    assert verdict.duplicates == 2
    assert verdict.duplicate_origins == ("tv_2 (confirmed), anchored anew: tv_1 ruled out by colour",
                                         "dog_3: origin unknown")
    assert verdict.as_dict()["duplicate_origins"] == list(verdict.duplicate_origins)


def test_anchors_left_undecided_are_counted_apart_from_duplicates_and_old_scorecards_have_none() -> None:
    card = scorecard()
    card["undecided"] = ["cup_1"]
    verdict = judge(card)
    assert (verdict.duplicates, verdict.undecided) == (0, 1)
    assert verdict.as_dict()["undecided"] == 1
    assert judge(scorecard()).undecided == 0
