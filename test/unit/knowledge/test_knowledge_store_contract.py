"""The contract every store keeps, run against memory, SQLite, MongoDB and the ROS client alike."""

import pytest

from merlin2_sailor.errors import KnowledgeError
from merlin2_sailor.knowledge import (
    Change,
    ChangeEvent,
    Condition,
    ItemKind,
    KnowledgeBase,
    Operation,
    Parameter,
    PddlAction,
    PddlObject,
    PddlType,
    Predicate,
    Proposition,
    Provenance,
)
from merlin2_sailor.ros.stores import open_store


def saved(kind: ItemKind, item) -> ChangeEvent:
    return ChangeEvent(Operation.SAVE, kind, item)


def deleted(kind: ItemKind, item) -> ChangeEvent:
    return ChangeEvent(Operation.DELETE, kind, item)


def fill(store: KnowledgeBase, items) -> None:
    store.apply([Change.save(item) for item in items])


class TestSaveAndGet:
    def test_every_kind_reads_back_equal(self, store, scene):
        fill(store, scene)
        for kind, access in (
            (PddlType, store.types),
            (PddlObject, store.objects),
            (Predicate, store.predicates),
            (Proposition, store.propositions),
            (PddlAction, store.actions),
        ):
            expected = [item for item in scene if isinstance(item, kind)]
            assert sorted(map(repr, access.get_all())) == sorted(map(repr, expected))
        assert store.objects.get("cup_1") == PddlObject("cup_1", "cup")
        goal = Proposition("robot_at", ("rb1", "living_room"), is_goal=True)
        assert store.propositions.get(goal.key) == goal
        assert store.objects.get("nothing") is None

    def test_saving_an_object_saves_its_type(self, store, recorded_events):
        events = store.objects.save(PddlObject("cup_1", "cup"))
        assert store.types.get("cup") == PddlType("cup")
        assert events == (
            saved(ItemKind.TYPE, PddlType("cup")),
            saved(ItemKind.OBJECT, PddlObject("cup_1", "cup")),
        )
        assert recorded_events == [events]

    def test_saving_a_type_saves_its_unknown_supertype(self, store):
        store.types.save(PddlType("mug", "container"))
        assert store.types.get("container") == PddlType("container")

    def test_saving_the_same_item_twice_is_idempotent(self, store, scene, recorded_events):
        fill(store, scene)
        recorded_events.clear()
        assert store.apply([Change.save(item) for item in scene]) == ()
        assert store.objects.save(PddlObject("cup_1", "cup")) == ()
        assert recorded_events == []
        assert len(store.objects.get_all()) == 4

    def test_saving_a_changed_item_updates_it(self, store, scene, recorded_events):
        fill(store, scene)
        recorded_events.clear()
        store.objects.save(PddlObject("cup_1", "container"))
        assert store.objects.get("cup_1") == PddlObject("cup_1", "container")
        assert recorded_events == [(saved(ItemKind.OBJECT, PddlObject("cup_1", "container")),)]

    def test_a_new_provenance_updates_the_same_fact(self, store, scene):
        fill(store, scene)
        perceived = Proposition("object_at", ("cup_1", "kitchen"), provenance=Provenance.PERCEIVED)
        assert store.propositions.save(perceived) == (saved(ItemKind.PROPOSITION, perceived),)
        matching = [p for p in store.propositions.get_all() if p.predicate == "object_at"]
        assert matching == [perceived]

    def test_a_fact_and_a_goal_of_the_same_atom_coexist(self, store, scene):
        fill(store, scene)
        store.propositions.save(Proposition("robot_at", ("rb1", "kitchen"), is_goal=True))
        robot_at = [p for p in store.propositions.get_all() if p.predicate == "robot_at"]
        assert len(robot_at) == 3

    def test_propositions_about_an_object(self, store, scene):
        fill(store, scene)
        assert set(store.propositions_about("rb1")) == {
            Proposition("robot_at", ("rb1", "kitchen")),
            Proposition("robot_at", ("rb1", "living_room"), is_goal=True),
        }
        assert store.propositions_about("unknown") == ()


class TestCascades:
    def test_deleting_an_object_deletes_its_propositions(self, store, scene, recorded_events):
        fill(store, scene)
        recorded_events.clear()
        events = store.objects.delete("cup_1")
        assert events == (
            deleted(ItemKind.PROPOSITION, Proposition("object_at", ("cup_1", "kitchen"))),
            deleted(ItemKind.OBJECT, PddlObject("cup_1", "cup")),
        )
        assert recorded_events == [events]
        assert store.propositions_about("cup_1") == ()
        assert store.types.get("cup") is not None

    def test_deleting_a_type_deletes_subtypes_objects_predicates_and_actions(self, store, scene):
        fill(store, scene)
        store.types.delete("container")
        assert store.types.get("cup") is None
        assert store.objects.get("cup_1") is None
        assert store.predicates.get("filled") is None
        assert store.propositions_about("cup_1") == ()
        assert store.objects.get("rb1") is not None
        assert store.actions.get("navigation") is not None

        store.types.delete("wp")
        assert store.predicates.get("robot_at") is None
        assert store.actions.get("navigation") is None
        assert store.propositions.get_all() == ()
        assert [o.name for o in store.objects.get_all()] == ["rb1"]

    def test_deleting_a_predicate_deletes_its_propositions_and_actions(self, store, scene):
        fill(store, scene)
        events = store.predicates.delete("robot_at")
        assert [event.kind for event in events] == [
            ItemKind.PROPOSITION,
            ItemKind.PROPOSITION,
            ItemKind.ACTION,
            ItemKind.PREDICATE,
        ]
        assert store.actions.get_all() == ()
        assert store.propositions.get_all() == (Proposition("object_at", ("cup_1", "kitchen")),)

    def test_delete_all_objects_takes_every_fact_but_keeps_types(self, store, scene):
        fill(store, scene)
        store.objects.delete_all()
        assert store.objects.get_all() == ()
        assert store.propositions.get_all() == ()
        assert len(store.types.get_all()) == 4

    def test_deleting_what_is_not_there_changes_nothing(self, store, recorded_events):
        assert store.objects.delete("ghost") == ()
        assert store.propositions.delete(Proposition("seen", ("ghost",))) == ()
        assert recorded_events == []

    def test_the_root_type_cannot_be_deleted(self, store):
        with pytest.raises(KnowledgeError, match="built-in"):
            store.types.delete("object")

    def test_save_then_delete_in_one_batch_reports_nothing(self, store, recorded_events):
        cup = PddlObject("cup_9", "cup")
        events = store.apply([Change.save(cup), Change.delete(cup), Change.delete(PddlType("cup"))])
        assert events == ()
        assert recorded_events == []
        assert store.objects.get_all() == ()


class TestRejections:
    def rejected(self, store, changes, message: str) -> None:
        before = {kind: set(store.get_all(kind)) for kind in ItemKind}
        with pytest.raises(KnowledgeError, match=message):
            store.apply(changes)
        assert {kind: set(store.get_all(kind)) for kind in ItemKind} == before

    def test_unknown_predicate(self, store, scene, recorded_events):
        fill(store, scene)
        recorded_events.clear()
        self.rejected(
            store,
            [Change.save(Proposition("holding", ("rb1", "cup_1")))],
            "unknown predicate 'holding'",
        )
        assert recorded_events == []

    def test_wrong_arity(self, store, scene):
        fill(store, scene)
        self.rejected(
            store,
            [Change.save(Proposition("robot_at", ("rb1",)))],
            r"gives 1 argument\(s\) to 'robot_at', which takes 2",
        )

    def test_unknown_object(self, store, scene):
        fill(store, scene)
        self.rejected(
            store,
            [Change.save(Proposition("robot_at", ("rb2", "kitchen")))],
            "unknown object 'rb2'",
        )

    def test_wrong_object_type(self, store, scene):
        fill(store, scene)
        self.rejected(
            store,
            [Change.save(Proposition("robot_at", ("cup_1", "kitchen")))],
            "object 'cup_1' has type 'cup', but argument 1 of 'robot_at' must be a 'robot'",
        )

    def test_subtypes_and_the_root_type_accept_their_descendants(self, store, scene):
        fill(store, scene)
        store.propositions.save(Proposition("filled", ("cup_1",)))
        store.propositions.save(Proposition("object_at", ("rb1", "living_room")))
        assert store.propositions.get(("filled", ("cup_1",), False)) is not None

    def test_a_whole_batch_is_rejected_when_one_change_is_invalid(self, store, scene):
        fill(store, scene)
        self.rejected(
            store,
            [
                Change.save(PddlObject("cup_2", "cup")),
                Change.delete_key(ItemKind.OBJECT, "kitchen"),
                Change.save(Proposition("robot_at", ("cup_2", "living_room"))),
            ],
            "must be a 'robot'",
        )
        assert store.propositions_about("kitchen") != ()

    def test_a_change_that_breaks_existing_facts_is_rejected(self, store, scene):
        fill(store, scene)
        self.rejected(store, [Change.save(PddlObject("rb1", "wp"))], "must be a 'robot'")
        self.rejected(store, [Change.save(Predicate("robot_at", ("robot",)))], "takes 1")
        store.propositions.save(Proposition("filled", ("cup_1",)))
        self.rejected(store, [Change.save(PddlType("cup", "robot"))], "must be a 'container'")

    def test_a_type_cycle_is_rejected(self, store):
        store.types.save(PddlType("cup", "container"))
        self.rejected(store, [Change.save(PddlType("container", "cup"))], "must be a tree")

    def test_an_action_must_type_check_against_its_predicates(self, store, scene):
        fill(store, scene)
        bad = PddlAction(
            "wave",
            parameters=(Parameter("place", "wp"),),
            conditions=(Condition("robot_at", ("place", "place"), "at start"),),
        )
        self.rejected(store, [Change.save(bad)], "parameter 'place' has type 'wp'")
        unknown = PddlAction("jump", conditions=(Condition("airborne", (), "at start"),))
        self.rejected(store, [Change.save(unknown)], "unknown predicate 'airborne'")

    def test_a_closed_store_refuses_writes(self, store_location):
        store = open_store(store_location)
        store.close()
        store.close()
        with pytest.raises(KnowledgeError, match="closed"):
            store.objects.save(PddlObject("cup_1", "cup"))


class TestEvents:
    def test_subscribers_hear_each_real_batch_once(self, store, scene, recorded_events):
        fill(store, scene)
        store.apply([])
        fill(store, scene)
        assert len(recorded_events) == 1
        reported = [event.item for event in recorded_events[0]]
        assert sorted(map(repr, reported)) == sorted(map(repr, scene))

    def test_saves_come_dependencies_first(self, store, scene, recorded_events):
        fill(store, list(reversed(scene)))
        kinds = [event.kind for event in recorded_events[0]]

        def last(kind: ItemKind) -> int:
            return max(i for i, k in enumerate(kinds) if k is kind)

        def first(kind: ItemKind) -> int:
            return kinds.index(kind)

        assert last(ItemKind.TYPE) < min(map(first, (ItemKind.PREDICATE, ItemKind.OBJECT)))
        assert last(ItemKind.PREDICATE) < min(map(first, (ItemKind.PROPOSITION, ItemKind.ACTION)))
        assert last(ItemKind.OBJECT) < first(ItemKind.PROPOSITION)

    def test_unsubscribed_and_failing_subscribers(self, store):
        heard: list = []
        unsubscribe = store.subscribe(heard.append)

        def failing(events):
            raise RuntimeError("subscriber bug")

        store.subscribe(failing)
        store.objects.save(PddlObject("cup_1", "cup"))
        assert store.objects.get("cup_1") is not None
        assert len(heard) == 1
        unsubscribe()
        unsubscribe()
        store.objects.save(PddlObject("cup_2", "cup"))
        assert len(heard) == 1


class TestPersistence:
    def test_items_survive_reopening(self, persistent_location, scene):
        with open_store(persistent_location) as store:
            fill(store, scene)
            store.objects.delete("living_room")
            expected = {kind: set(store.get_all(kind)) for kind in ItemKind}
        with open_store(persistent_location) as store:
            assert {kind: set(store.get_all(kind)) for kind in ItemKind} == expected
            assert store.propositions_about("cup_1") == (
                Proposition("object_at", ("cup_1", "kitchen")),
            )

    def test_updates_and_cascades_are_persisted(self, persistent_location, scene):
        with open_store(persistent_location) as store:
            fill(store, scene)
            store.propositions.save(
                Proposition("object_at", ("cup_1", "kitchen"), provenance=Provenance.EXPECTED)
            )
            store.types.delete("container")
        with open_store(persistent_location) as store:
            assert store.objects.get("cup_1") is None
            assert store.types.get("cup") is None
            assert set(store.propositions.get_all()) == {
                Proposition("robot_at", ("rb1", "kitchen")),
                Proposition("robot_at", ("rb1", "living_room"), is_goal=True),
            }
