"""The demo names every object before the world changes it, from the anchors the robot reported."""

from __future__ import annotations

from merlin2_sailor_demos.report.naming import symbols_before_change
from merlin2_sailor_demos.report.scorecard import AnchorRecord, TrueObject

RED_MUG_AT_START = TrueObject("red_mug", "cup", (2.10, 2.10, 0.81))
GREEN_MUG = TrueObject("green_mug", "cup", (1.60, 1.90, 0.81))
BOOK = TrueObject("book", "book", (2.80, 0.35, 1.03))
AT_START = [RED_MUG_AT_START, GREEN_MUG, BOOK]


def moved(obj: TrueObject, position: tuple[float, float, float]) -> TrueObject:
    return TrueObject(obj.id, obj.class_name, position)


def test_each_object_is_named_by_the_anchor_where_it_was_put() -> None:
    anchors = [AnchorRecord("cup_3", "cup", (2.08, 2.12, 0.80)), AnchorRecord("cup_2", "cup", (1.61, 1.90, 0.80)),
               AnchorRecord("book_1", "book", (2.79, 0.35, 1.03))]
    assert symbols_before_change(AT_START, RED_MUG_AT_START, anchors) == {
        "red_mug": "cup_3", "green_mug": "cup_2", "book": "book_1"}


def test_a_missing_anchor_still_names_what_the_robot_saw_there_and_a_confirmed_one_comes_first() -> None:
    anchors = [AnchorRecord("cup_9", "cup", (2.30, 2.10, 0.80), state="missing"),
               AnchorRecord("cup_3", "cup", (2.12, 2.10, 0.80)),
               AnchorRecord("cup_2", "cup", (1.60, 1.92, 0.80), state="missing"),
               AnchorRecord("cup_5", "cup", (2.11, 2.10, 0.80), state="tentative")]
    named = symbols_before_change(AT_START, RED_MUG_AT_START, anchors)
    assert named == {"red_mug": "cup_3", "green_mug": "cup_2"}  # cup_9 is farther than cup_3 but missing


def test_a_target_moved_in_view_is_named_where_it_stands_now_even_while_its_anchor_is_missing() -> None:
    # CI, 4 December: the red mug slid 0.7 m while the camera watched, its anchor followed it, and
    # that anchor was missing for three frames just as the demo pointed at it.
    now = moved(RED_MUG_AT_START, (1.42, 2.28, 0.81))
    for state in ("confirmed", "missing"):
        anchors = [AnchorRecord("cup_3", "cup", (1.43, 2.27, 0.80), state=state),
                   AnchorRecord("cup_2", "cup", (1.60, 1.90, 0.80))]
        assert symbols_before_change(AT_START, now, anchors)["red_mug"] == "cup_3", state


def test_the_moved_target_never_takes_a_symbol_that_already_names_another_object() -> None:
    now = moved(RED_MUG_AT_START, (1.55, 1.95, 0.81))  # now beside the green mug, whose anchor is nearer
    anchors = [AnchorRecord("cup_2", "cup", (1.60, 1.90, 0.80))]
    named = symbols_before_change(AT_START, now, anchors)
    assert named == {"green_mug": "cup_2"}


def test_an_object_moved_unseen_keeps_the_name_of_the_anchor_where_it_was() -> None:
    now = moved(RED_MUG_AT_START, (5.00, 7.00, 0.80))
    anchors = [AnchorRecord("cup_3", "cup", (2.10, 2.10, 0.80), state="missing"),
               AnchorRecord("cup_8", "cup", (5.00, 7.00, 0.80))]
    assert symbols_before_change(AT_START, now, anchors)["red_mug"] == "cup_3"


def test_an_object_no_anchor_claims_is_not_named() -> None:
    anchors = [AnchorRecord("cup_2", "cup", (1.60, 1.90, 0.80)),
               AnchorRecord("cup_4", "cup", (2.10, 2.10, 0.80), state="tentative")]
    assert "red_mug" not in symbols_before_change(AT_START, RED_MUG_AT_START, anchors)
    assert "red_mug" not in symbols_before_change(AT_START, None, anchors)
