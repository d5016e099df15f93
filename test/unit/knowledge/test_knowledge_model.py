"""Model items validate themselves on construction, with messages that say what to do."""

import pytest

from merlin2_sailor.errors import KnowledgeError
from merlin2_sailor.knowledge import (
    Condition,
    Effect,
    Parameter,
    PddlAction,
    PddlObject,
    PddlType,
    Predicate,
    Proposition,
    Provenance,
    Timing,
)


@pytest.mark.parametrize(
    "build",
    [
        lambda: PddlObject("cup - 3", "cup"),
        lambda: PddlObject("cup_3", "Cup"),
        lambda: PddlType("and"),
        lambda: Predicate("object_at", ("object", ") (:goal")),
        lambda: Proposition("seen", ("cup 1",)),
        lambda: Parameter("?origin", "wp"),
        lambda: PddlAction("go-to"),
    ],
)
def test_invalid_names_are_refused_with_a_repair(build):
    with pytest.raises(KnowledgeError, match="to_identifier"):
        build()


def test_lists_are_stored_as_tuples_so_items_hash():
    predicate = Predicate("object_at", ["object", "wp"])
    proposition = Proposition("object_at", ["cup_1", "kitchen"])
    assert predicate.parameter_types == ("object", "wp") and predicate.arity == 2
    assert {proposition, Proposition("object_at", ("cup_1", "kitchen"))} == {proposition}


def test_a_sequence_of_names_must_not_be_a_string():
    with pytest.raises(KnowledgeError, match="sequence of names"):
        Predicate("seen", "object")


def test_the_root_type_is_built_in():
    with pytest.raises(KnowledgeError, match="built-in root type"):
        PddlType("object")
    with pytest.raises(KnowledgeError, match="its own supertype"):
        PddlType("cup", "cup")


def test_provenance_is_not_part_of_a_facts_identity():
    expected = Proposition("seen", ("cup_1",), provenance=Provenance.EXPECTED)
    perceived = Proposition("seen", ("cup_1",), provenance=Provenance.PERCEIVED)
    assert expected != perceived and expected.key == perceived.key
    assert str(Proposition("robot_at", ("rb1", "wp1"), is_goal=True)) == "goal robot_at(rb1, wp1)"


def test_times_may_be_written_as_text():
    assert Condition("robot_at", ("r",), "over all").time is Timing.OVER_ALL
    with pytest.raises(KnowledgeError, match="unknown time 'sometimes'"):
        Condition("robot_at", ("r",), "sometimes")
    with pytest.raises(KnowledgeError, match="cannot happen 'over all'"):
        Effect("robot_at", ("r",), Timing.OVER_ALL)


class TestAction:
    def test_literals_use_only_parameters(self):
        with pytest.raises(KnowledgeError, match=r"uses \['there'\], which are not its parameters"):
            PddlAction(
                "go",
                parameters=(Parameter("here", "wp"),),
                effects=(Effect("robot_at", ("there",), "at end"),),
            )

    def test_durative_actions_need_times_and_a_positive_duration(self):
        with pytest.raises(KnowledgeError, match="needs a time"):
            PddlAction("go", conditions=(Condition("ready"),))
        with pytest.raises(KnowledgeError, match="positive finite duration"):
            PddlAction("go", duration=0.0)

    def test_instantaneous_actions_have_no_times(self):
        with pytest.raises(KnowledgeError, match="cannot have a time"):
            PddlAction("go", durative=False, effects=(Effect("done", (), "at end"),))
        action = PddlAction("go", durative=False, effects=[Effect("done")], duration=0.0)
        assert action.effects == (Effect("done"),)

    def test_parameters_are_unique(self):
        with pytest.raises(KnowledgeError, match=r"repeats parameter\(s\) \['a'\]"):
            PddlAction("go", parameters=(Parameter("a", "wp"), Parameter("a", "robot")))

    def test_conditions_and_effects_are_not_interchangeable(self):
        with pytest.raises(KnowledgeError, match="must be Condition items"):
            PddlAction("go", durative=False, conditions=(Effect("done"),))

    def test_parameter_type(self):
        action = PddlAction("go", parameters=(Parameter("to", "wp"),))
        assert action.parameter_type("to") == "wp"
        with pytest.raises(KnowledgeError, match="no parameter 'from'"):
            action.parameter_type("from")
