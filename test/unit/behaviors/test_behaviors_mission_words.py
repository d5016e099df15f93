"""Goals typed three ways parse alike; the running account words what an operator needs."""

import pytest

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.knowledge import ChangeEvent, ItemKind, Operation, PddlObject, Proposition, Provenance
from merlin2_sailor_behaviors.mission import AnchorEventWording, describe_fact_changes, parse_goal, parse_goals


@pytest.mark.parametrize(
    "text", ["robot_near(cup_2)", "(robot_near cup_2)", "robot_near cup_2", "  Robot_Near( cup_2 ) "]
)
def test_a_goal_may_be_typed_three_ways(text):
    goal = parse_goal(text)
    assert (goal.predicate, goal.objects, goal.is_goal) == ("robot_near", ("cup_2",), True)


def test_goals_with_several_or_no_objects():
    assert parse_goal("object_at(cup_1, kitchen)").objects == ("cup_1", "kitchen")
    assert parse_goal("(object_at cup_1 kitchen)").objects == ("cup_1", "kitchen")
    assert parse_goal("done()").objects == ()


@pytest.mark.parametrize("text", ["", "robot_near(cup 2", "robot near(cup)", "robot_near(cup-2))", "at(a b) c"])
def test_malformed_goals_are_one_clear_error(text):
    with pytest.raises(ConfigurationError, match="goal"):
        parse_goal(text)


def test_a_mission_needs_a_goal():
    with pytest.raises(ConfigurationError, match="at least one goal"):
        parse_goals(["", "  "])
    assert len(parse_goals(["robot_at(kitchen)", "explored(bedroom)"])) == 2


def test_fact_changes_are_worded_with_their_provenance():
    events = [
        ChangeEvent(Operation.SAVE, ItemKind.PROPOSITION,
                    Proposition("object_at", ("cup_2", "bedroom"), provenance=Provenance.PERCEIVED)),
        ChangeEvent(Operation.DELETE, ItemKind.PROPOSITION, Proposition("object_at", ("cup_2", "kitchen"))),
        ChangeEvent(Operation.SAVE, ItemKind.PROPOSITION, Proposition("robot_near", ("cup_2",), is_goal=True)),
        ChangeEvent(Operation.SAVE, ItemKind.PROPOSITION, Proposition("visible", ("cup_2",))),
        ChangeEvent(Operation.SAVE, ItemKind.OBJECT, PddlObject("cup_2", "cup")),
    ]
    assert describe_fact_changes(events) == ["+ object_at(cup_2, bedroom)  [perceived]", "- object_at(cup_2, kitchen)"]


def test_anchor_events_worded_only_when_notable():
    wording = AnchorEventWording()
    assert wording.describe("acquired", "cup_2", "cup") is None  # tentative: maybe a false positive
    assert wording.describe("confirmed", "cup_2", "cup") == "anchor cup_2 (cup) anchored"
    assert wording.describe("reacquired", "cup_2") is None  # seen again a frame later: routine
    assert wording.describe("missing", "cup_2", "cup") == "anchor cup_2 (cup) missing"
    assert wording.describe("reacquired", "cup_2") is None  # one sighting: maybe a false detection
    assert wording.describe("confirmed", "cup_2") == "anchor cup_2 reacquired after being missing"
    assert wording.describe("reacquired", "cup_2") is None
    assert wording.describe("confirmed", "cup_2", reason="expectation") == "anchor cup_2 confirmed where expected"
    assert wording.describe("retracted", "cup_1", reason="expected place seen empty") == (
        "anchor cup_1 retracted: expected place seen empty"
    )
    assert wording.describe("forgotten", "bird_9", reason="missing too long") is None  # never confirmed
    assert wording.describe("forgotten", "cup_2", "cup", "requested") == "anchor cup_2 (cup) forgotten: requested"
