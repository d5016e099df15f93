"""KantStore against a stand-in that follows KANT's documented DTO and DAO API."""

from __future__ import annotations

import sys

import pytest

from merlin2_sailor.errors import DependencyError, KnowledgeError
from merlin2_sailor.knowledge import (
    Change,
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
from merlin2_sailor.knowledge.kant_store import KantStore, import_kant_dto

from .kant_stand_in import KANT_DTO, InMemoryDaoFactory, PddlObjectDto, PddlTypeDto

NAVIGATION = PddlAction(
    "navigation",
    parameters=(Parameter("origin", "wp"), Parameter("destination", "wp")),
    conditions=(Condition("robot_at", ("origin",), "at start"),),
    effects=(Effect("robot_at", ("origin",), "at start", is_negative=True),
             Effect("robot_at", ("destination",), "at end")),
    duration=30.0,
)
SCENE = [
    PddlType("wp"), PddlType("cup"),
    PddlObject("kitchen", "wp"), PddlObject("cup_1", "cup"),
    Predicate("robot_at", ("wp",)), Predicate("object_at", ("cup", "wp")),
    Proposition("robot_at", ("kitchen",)),
    Proposition("object_at", ("cup_1", "kitchen"), provenance=Provenance.PERCEIVED),
    Proposition("object_at", ("cup_1", "kitchen"), is_goal=True),
    NAVIGATION,
]


@pytest.fixture
def kant() -> InMemoryDaoFactory:
    return InMemoryDaoFactory()


@pytest.fixture
def store(kant: InMemoryDaoFactory) -> KantStore:
    store = KantStore(kant, dto_module=KANT_DTO)
    store.apply([Change.save(item) for item in SCENE])
    return store


def test_every_kind_reaches_kant_and_reads_back_equal(store, kant) -> None:
    assert set(kant.objects.items) == {"kitchen", "cup_1"}
    assert kant.objects.items["cup_1"].get_type().get_name() == "cup"
    assert len(kant.propositions.items) == 3
    action = kant.actions.items["navigation"]
    assert (action.get_duration(), [c.get_time() for c in action.get_effects()]) == (30.0, ["at start", "at end"])
    fresh = KantStore(kant, dto_module=KANT_DTO)  # a second adapter reads only what KANT holds
    for kind, items in ((ItemKind.TYPE, SCENE[:2]), (ItemKind.OBJECT, SCENE[2:4]),
                        (ItemKind.PREDICATE, SCENE[4:6]), (ItemKind.ACTION, [NAVIGATION])):
        assert set(fresh.get_all(kind)) == set(items)
    assert {p.key for p in fresh.get_all(ItemKind.PROPOSITION)} == {p.key for p in SCENE[6:9]}


def test_deleting_an_object_deletes_its_facts_in_kant(store, kant) -> None:
    events = store.objects.delete("cup_1")
    assert {type(event.item).__name__ for event in events} == {"PddlObject", "Proposition"}
    assert set(kant.objects.items) == {"kitchen"}
    assert list(kant.propositions.items) == [("robot_at", ("kitchen",), False)]


def test_an_invalid_batch_is_refused_before_anything_reaches_kant(store, kant) -> None:
    with pytest.raises(KnowledgeError, match="robot_at"):
        store.apply([Change.save(PddlObject("cup_2", "cup")),
                     Change.save(Proposition("robot_at", ("kitchen", "cup_2")))])
    assert "cup_2" not in kant.objects.items


def test_what_other_merlin2_components_write_to_kant_is_seen(store, kant) -> None:
    kant.objects.save(PddlObjectDto(PddlTypeDto("wp"), "bedroom"))  # written by a mission
    store.apply([Change.save(Proposition("robot_at", ("bedroom",)))])
    assert store.objects.get("bedroom") == PddlObject("bedroom", "wp")


def test_provenance_is_kept_for_own_facts_and_foreign_facts_read_as_declared(store, kant) -> None:
    assert store.propositions.get(("object_at", ("cup_1", "kitchen"), False)).provenance is Provenance.PERCEIVED
    assert KantStore(kant, dto_module=KANT_DTO).propositions.get(
        ("object_at", ("cup_1", "kitchen"), False)).provenance is Provenance.DECLARED




def test_a_refusal_from_kant_is_a_knowledge_error(store, kant) -> None:
    kant.objects.refuse = True
    with pytest.raises(KnowledgeError, match="KANT refused to save object"):
        store.objects.save(PddlObject("cup_2", "cup"))


def test_without_kant_installed_the_error_says_how_to_get_it(monkeypatch) -> None:
    monkeypatch.setitem(sys.modules, "kant_dto", None)  # as if not installed, even under SAILOR_UPSTREAM
    with pytest.raises(DependencyError, match="build KANT"):
        import_kant_dto()
