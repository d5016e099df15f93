"""How SAILOR's type tree and durations are projected onto KANT's flat, integer world (no KANT needed)."""

import pytest

from merlin2_sailor.knowledge import (
    Condition,
    Effect,
    ItemKind,
    Parameter,
    PddlAction,
    PddlObject,
    PddlType,
    Predicate,
    Proposition,
    Provenance,
)
from merlin2_sailor.knowledge.kant_projection import KantKinds, KantProjection, kant_duration

from .conftest import kitchen_scene


def test_types_that_meet_in_a_fact_share_the_most_general_of_them():
    kinds = KantKinds(kitchen_scene())
    # cup_1 fills object_at's ``object``: its type joins object's kind.
    assert kinds("cup") == kinds("object") == "object"
    assert kinds("container") == "container"  # filled(?c - container) holds no fact yet
    assert kinds("wp") == "wp"
    assert kinds("robot") == "robot"
    # Once cup_1 is filled too, container meets object through it.
    kinds = KantKinds([*kitchen_scene(), Proposition("filled", ("cup_1",))])
    assert kinds("cup") == kinds("container") == kinds("object") == "object"


def test_types_that_never_meet_stay_themselves():
    kinds = KantKinds([PddlType("container"), PddlType("cup", "container"), PddlType("glass", "container")])
    assert [kinds(name) for name in ("cup", "glass", "container", "unheard_of")] == [
        "cup", "glass", "container", "unheard_of"]


def test_siblings_meeting_in_a_parameter_take_their_common_ancestor():
    items = [
        PddlType("container"), PddlType("cup", "container"), PddlType("glass", "container"),
        PddlType("wp"),
        Predicate("next_to", ("cup", "glass")),
        PddlObject("cup_1", "cup"), PddlObject("glass_1", "glass"),
        Proposition("next_to", ("cup_1", "glass_1")),
        Proposition("next_to", ("glass_1", "cup_1")),
    ]
    kinds = KantKinds(items)
    assert kinds("cup") == kinds("glass") == "container"
    assert kinds("wp") == "wp"


def test_actions_join_their_parameter_types_to_the_predicates_they_use():
    action = PddlAction(
        "wipe", (Parameter("target", "cup"),),
        (Condition("filled", ("target",), "at start"),), (Effect("filled", ("target",), "at end", True),),
    )
    kinds = KantKinds([PddlType("container"), PddlType("cup", "container"), Predicate("filled", ("container",)),
                       action])
    assert kinds("cup") == "container"


def test_projection_of_every_kind_and_its_restoration():
    projection = KantProjection()
    scene = [*kitchen_scene(), Proposition("filled", ("cup_1",))]
    projection.update(scene)
    cup = PddlObject("cup_1", "cup")
    assert projection.project(cup) == PddlObject("cup_1", "object")
    assert projection.project(PddlType("cup", "container")) == PddlType("cup")
    assert projection.project(Predicate("filled", ("container",))) == Predicate("filled", ("object",))
    fact = Proposition("object_at", ("cup_1", "kitchen"), provenance=Provenance.PERCEIVED)
    assert projection.project(fact) == Proposition("object_at", ("cup_1", "kitchen"))
    # Read back, KANT's items are what SAILOR wrote, when KANT still holds their projection.
    projection.remember(ItemKind.OBJECT, cup)
    projection.remember(ItemKind.PROPOSITION, fact)
    assert projection.restore(ItemKind.OBJECT, PddlObject("cup_1", "object")) == cup
    assert projection.restore(ItemKind.PROPOSITION, Proposition("object_at", ("cup_1", "kitchen"))) == fact
    # Someone else re-typed it in KANT: KANT's item wins.
    assert projection.restore(ItemKind.OBJECT, PddlObject("cup_1", "wp")) == PddlObject("cup_1", "wp")
    projection.forget(ItemKind.OBJECT, cup)
    assert projection.restore(ItemKind.OBJECT, PddlObject("cup_1", "object")) == PddlObject("cup_1", "object")


@pytest.mark.parametrize(("seconds", "whole"), [(2.5, 3), (3.0, 3), (0.2, 1), (10.0, 10), (59.0000000001, 59)])
def test_durations_round_up_to_whole_seconds(seconds, whole):
    assert kant_duration(seconds) == whole


def test_an_action_is_given_whole_seconds_and_its_parameters_kinds():
    projection = KantProjection()
    action = PddlAction("wait", (Parameter("place", "wp"),), duration=2.5)
    assert projection.project(action) == PddlAction("wait", (Parameter("place", "wp"),), duration=3.0)
