"""KnowledgeSync writes anchors by diff, lets perception overrule predictions, and keeps off
what it did not create."""

import pytest

from merlin2_sailor.errors import KnowledgeError
from merlin2_sailor.knowledge import (
    Change,
    ChangeEvent,
    Grounding,
    GroundingConfig,
    ItemKind,
    KnowledgeSync,
    Operation,
    PddlObject,
    Predicate,
    Proposition,
    Provenance,
    open_store,
)

MAP = {"map": {"waypoints": {"kitchen": [0, 0], "table": [3, 0], "door": [6, 0]}}}


def perceived(predicate, *objects):
    return Proposition(predicate, objects, provenance=Provenance.PERCEIVED)


def expected(predicate, *objects):
    return Proposition(predicate, objects, provenance=Provenance.EXPECTED)


@pytest.fixture
def mission_store():
    """A store where a mission has already declared a robot, its place and a goal."""
    with open_store() as store:
        store.apply(
            [
                Change.save(PddlObject("rb1", "robot")),
                Change.save(PddlObject("kitchen", "wp")),
                Change.save(Predicate("robot_at", ("robot", "wp"))),
                Change.save(Proposition("robot_at", ("rb1", "kitchen"))),
                Change.save(Predicate("object_at", ("object", "wp"))),
            ]
        )
        yield store


@pytest.fixture
def sync(mission_store):
    knowledge_sync = KnowledgeSync(mission_store, Grounding(GroundingConfig.from_mapping(MAP)))
    yield knowledge_sync
    knowledge_sync.close()


def facts_about(store, name):
    return set(store.propositions_about(name))


def changed_items(events):
    return {(event.operation, event.item) for event in events}


def test_the_first_sync_declares_and_adds_everything(sync, mission_store, make_anchor):
    sync.sync([make_anchor("cup_1", "cup", 0.2, 0), make_anchor("book_1", "book", 3, 0.3)])
    assert mission_store.objects.get("cup_1") == PddlObject("cup_1", "object")
    assert mission_store.objects.get("table") == PddlObject("table", "wp")
    assert facts_about(mission_store, "cup_1") == {
        perceived("seen", "cup_1"),
        perceived("visible", "cup_1"),
        perceived("object_at", "cup_1", "kitchen"),
    }
    assert perceived("object_at", "book_1", "table") in facts_about(mission_store, "book_1")


def test_an_unchanged_frame_sends_nothing(sync, make_anchor):
    anchors = [make_anchor("cup_1", "cup", 0.2, 0)]
    sync.sync(anchors)
    assert sync.plan(anchors).changes == ()
    assert sync.sync(anchors) == ()


def test_a_moved_anchor_changes_only_its_location(sync, make_anchor):
    sync.sync([make_anchor("cup_1", "cup", 0.2, 0), make_anchor("book_1", "book", 3, 0)])
    events = sync.sync([make_anchor("cup_1", "cup", 5.8, 0), make_anchor("book_1", "book", 3, 0)])
    assert changed_items(events) == {
        (Operation.DELETE, perceived("object_at", "cup_1", "kitchen")),
        (Operation.SAVE, perceived("object_at", "cup_1", "door")),
    }


def test_a_sync_is_one_batch(sync, mission_store, make_anchor):
    batches: list = []
    mission_store.subscribe(batches.append)
    sync.sync([make_anchor(f"cup_{i}", "cup", i, 0) for i in range(1, 20)])
    sync.sync([make_anchor(f"cup_{i}", "cup", i + 3, 0) for i in range(1, 20)])
    assert len(batches) == 2


def test_a_forgotten_anchor_takes_its_object_and_facts_but_nothing_else(
    sync, mission_store, make_anchor
):
    sync.sync([make_anchor("cup_1", "cup", 0.2, 0)])
    mission_store.propositions.save(Proposition("object_at", ("cup_1", "kitchen"), is_goal=True))
    events = sync.sync([])
    assert mission_store.objects.get("cup_1") is None
    assert facts_about(mission_store, "cup_1") == set()
    assert (Operation.DELETE, PddlObject("cup_1", "object")) in changed_items(events)
    assert mission_store.objects.get("rb1") == PddlObject("rb1", "robot")
    assert mission_store.objects.get("kitchen") is not None
    assert facts_about(mission_store, "rb1") == {Proposition("robot_at", ("rb1", "kitchen"))}


def test_anchors_enter_and_leave_with_their_state(sync, mission_store, make_anchor):
    sync.sync([make_anchor("cup_1", "cup", 0, 0, state="tentative")])
    assert mission_store.objects.get("cup_1") is None
    sync.sync([make_anchor("cup_1", "cup", 0, 0, state="confirmed")])
    assert mission_store.objects.get("cup_1") is not None
    sync.sync([make_anchor("cup_1", "cup", 0, 0, state="forgotten")])
    assert mission_store.objects.get("cup_1") is None


class TestPerceptionOutranksExpectation:
    def test_a_contradicted_expectation_is_retracted(self, sync, mission_store, make_anchor):
        sync.sync([make_anchor("cup_1", "cup", 0.2, 0)])
        # An action predicted the cup would end at the table; the camera still sees it here.
        mission_store.apply(
            [
                Change.delete(perceived("object_at", "cup_1", "kitchen")),
                Change.save(expected("object_at", "cup_1", "table")),
            ]
        )
        events = sync.sync([make_anchor("cup_1", "cup", 0.2, 0)])
        assert changed_items(events) == {
            (Operation.DELETE, expected("object_at", "cup_1", "table")),
            (Operation.SAVE, perceived("object_at", "cup_1", "kitchen")),
        }

    def test_a_confirmed_expectation_becomes_perceived(self, sync, mission_store, make_anchor):
        sync.sync([make_anchor("cup_1", "cup", 0.2, 0)])
        mission_store.apply(
            [
                Change.delete(perceived("object_at", "cup_1", "kitchen")),
                Change.save(expected("object_at", "cup_1", "table")),
            ]
        )
        events = sync.sync([make_anchor("cup_1", "cup", 3.1, 0)])
        assert changed_items(events) == {
            (Operation.SAVE, perceived("object_at", "cup_1", "table")),
        }

    def test_out_of_view_anchors_do_not_undo_an_action(self, sync, mission_store, make_anchor):
        sync.sync([make_anchor("cup_1", "cup", 0.2, 0)])
        # The robot carried the cup away; its anchor is out of view at its old place.
        mission_store.apply(
            [
                Change.delete(perceived("object_at", "cup_1", "kitchen")),
                Change.save(expected("object_at", "cup_1", "door")),
            ]
        )
        events = sync.sync([make_anchor("cup_1", "cup", 0.2, 0, visible=False)])
        assert changed_items(events) == {(Operation.DELETE, perceived("visible", "cup_1"))}
        assert expected("object_at", "cup_1", "door") in facts_about(mission_store, "cup_1")

    def test_an_anchor_gone_missing_loses_its_location(self, sync, mission_store, make_anchor):
        sync.sync([make_anchor("cup_1", "cup", 0.2, 0), make_anchor("cup_2", "cup", 3.0, 0)])
        # A navigation announced cup_2 at the table (EXPECTED); the camera then saw both places empty.
        mission_store.apply(
            [
                Change.delete(perceived("object_at", "cup_2", "table")),
                Change.save(expected("object_at", "cup_2", "table")),
            ]
        )
        events = sync.sync(
            [
                make_anchor("cup_1", "cup", 0.2, 0, state="missing", visible=False),
                make_anchor("cup_2", "cup", 3.0, 0, state="missing", visible=False),
            ]
        )
        assert changed_items(events) == {
            (Operation.DELETE, perceived("object_at", "cup_1", "kitchen")),
            (Operation.DELETE, perceived("visible", "cup_1")),
            (Operation.SAVE, perceived("missing", "cup_1")),
            (Operation.DELETE, expected("object_at", "cup_2", "table")),
            (Operation.DELETE, perceived("visible", "cup_2")),
            (Operation.SAVE, perceived("missing", "cup_2")),
        }
        # Reacquired elsewhere: the missing fact goes, the new location comes.
        sync.sync([make_anchor("cup_1", "cup", 6.1, 0)])
        assert facts_about(mission_store, "cup_1") == {
            perceived("seen", "cup_1"), perceived("visible", "cup_1"), perceived("object_at", "cup_1", "door")
        }

    def test_declared_facts_are_left_alone(self, sync, mission_store, make_anchor):
        sync.sync([make_anchor("cup_1", "cup", 0.2, 0)])
        mission_store.propositions.save(Proposition("object_at", ("cup_1", "table")))
        assert sync.sync([make_anchor("cup_1", "cup", 0.2, 0)]) == ()


class TestForeignItems:
    def test_an_object_declared_before_is_kept_when_its_anchor_goes(
        self, mission_store, make_anchor
    ):
        mission_store.apply(
            [
                Change.save(PddlObject("cup_1", "cup")),
                Change.save(Proposition("object_at", ("cup_1", "kitchen"))),
            ]
        )
        with_types = GroundingConfig.from_mapping({**MAP, "class_types": {"cup": "cup"}})
        sync = KnowledgeSync(mission_store, Grounding(with_types))
        sync.sync([make_anchor("cup_1", "cup", 3, 0)])
        sync.sync([])
        assert mission_store.objects.get("cup_1") == PddlObject("cup_1", "cup")
        assert facts_about(mission_store, "cup_1") == {
            Proposition("object_at", ("cup_1", "kitchen"))
        }

    def test_deleted_declarations_are_saved_again(self, sync, mission_store, make_anchor):
        sync.sync([make_anchor("cup_1", "cup", 3, 0)])
        mission_store.objects.delete("table")
        events = sync.sync([make_anchor("cup_1", "cup", 3, 0)])
        assert (Operation.SAVE, PddlObject("table", "wp")) in changed_items(events)
        assert perceived("object_at", "cup_1", "table") in facts_about(mission_store, "cup_1")

    def test_a_deleted_anchor_object_is_recreated_while_the_anchor_lives(
        self, sync, mission_store, make_anchor
    ):
        sync.sync([make_anchor("cup_1", "cup", 0, 0)])
        mission_store.objects.delete("cup_1")
        sync.sync([make_anchor("cup_1", "cup", 0, 0)])
        assert len(facts_about(mission_store, "cup_1")) == 3


def test_a_rejected_batch_changes_nothing_and_is_retried(mission_store, make_anchor):
    # A mission gave "visible" another meaning, which the grounding's declaration would break.
    mission_store.predicates.save(Predicate("visible", ("robot", "wp")))
    mission_store.propositions.save(Proposition("visible", ("rb1", "kitchen")))
    sync = KnowledgeSync(mission_store, Grounding(GroundingConfig.from_mapping(MAP)))
    with pytest.raises(KnowledgeError, match=r"visible\(rb1, kitchen\) gives 2 argument"):
        sync.sync([make_anchor("cup_1", "cup", 0, 0)])
    assert mission_store.objects.get("cup_1") is None
    mission_store.predicates.delete("visible")
    sync.sync([make_anchor("cup_1", "cup", 0, 0)])
    assert mission_store.objects.get("cup_1") is not None
    assert mission_store.predicates.get("visible") == Predicate("visible", ("object",))


def test_sync_works_the_same_on_a_persistent_store(persistent_location, make_anchor):
    with open_store(persistent_location) as store:
        sync = KnowledgeSync(store, Grounding(GroundingConfig.from_mapping(MAP)))
        sync.sync([make_anchor("cup_1", "cup", 0, 0)])
        events = sync.sync([make_anchor("cup_1", "cup", 3, 0)])
        assert len(events) == 2
    with open_store(persistent_location) as store:
        assert perceived("object_at", "cup_1", "table") in facts_about(store, "cup_1")
        assert store.objects.get("kitchen") is not None


def test_events_report_the_change_kinds(sync, make_anchor):
    events = sync.sync([make_anchor("cup_1", "cup", 0, 0)])
    assert ChangeEvent(Operation.SAVE, ItemKind.OBJECT, PddlObject("cup_1", "object")) in events


def test_after_a_restart_a_sync_that_owns_the_old_objects_still_cleans_them_up(
    sync, mission_store, make_anchor
):
    sync.sync([make_anchor("cup_1", "cup", 0.2, 0), make_anchor("book_1", "book", 3, 0.3)])
    owned = sync.owned_objects
    assert owned == {"cup_1", "book_1"}
    sync.close()  # the anchoring node crashed; its anchors come back from its snapshot

    unaware = KnowledgeSync(mission_store, Grounding(GroundingConfig.from_mapping(MAP)))
    assert not any(change.item == PddlObject("book_1", "object") for change in
                   unaware.plan([make_anchor("cup_1", "cup", 0.2, 0)]).changes)
    unaware.close()

    restarted = KnowledgeSync(mission_store, Grounding(GroundingConfig.from_mapping(MAP)), owned=owned)
    restarted.sync([make_anchor("cup_1", "cup", 0.2, 0)])  # book_1 was forgotten meanwhile
    assert mission_store.objects.get("book_1") is None
    assert facts_about(mission_store, "book_1") == set()
    assert mission_store.objects.get("cup_1") == PddlObject("cup_1", "object")
    assert mission_store.objects.get("rb1") == PddlObject("rb1", "robot")  # never ours
    restarted.close()
