"""The anchoring node's persistence, without ROS: state file, frozen views, and the worker that
syncs the knowledge base and saves anchors off the hot path."""

from __future__ import annotations

import json

import numpy as np
import pytest

from merlin2_sailor.anchoring.anchor import Anchor, AnchorState
from merlin2_sailor.anchoring.anchor_view import AnchorView, views_of
from merlin2_sailor.anchoring.persistence_worker import AnchorsCopy, PersistenceWorker
from merlin2_sailor.anchoring.state_file import AnchoringStateFile
from merlin2_sailor.errors import ConfigurationError, KnowledgeError
from merlin2_sailor.knowledge import Grounding, GroundingConfig, open_store

GROUNDING = Grounding(GroundingConfig.from_mapping({
    "map": {"waypoints": [{"name": "kitchen", "x": 1.0, "y": 0.0}]}, "ungrounded_states": ["forgotten"]}))


def anchor(symbol: str, x: float) -> Anchor:
    return Anchor(symbol=symbol, class_name=symbol.rsplit("_", 1)[0], position=np.array([x, 0.0, 0.8]),
                  size=np.array([0.1, 0.1, 0.1]), first_seen=1.0, last_seen=2.0, state=AnchorState.CONFIRMED)


class FlakyStore:
    """A knowledge base that can be made to fail, lose its answers, and restart empty."""

    def __init__(self) -> None:
        self.store = open_store("memory")
        self.down = False
        self.answers_lost = False  # applies a batch, then fails as if killed before answering
        self.opened = 0

    def open(self):
        self.opened += 1
        outer = self

        class Proxy:
            def __getattr__(self, name):
                if outer.down:
                    raise KnowledgeError("knowledge base unreachable")
                if name == "apply" and outer.answers_lost:
                    def apply_then_die(changes):
                        outer.store.apply(changes)
                        raise KnowledgeError("the knowledge base did not answer")
                    return apply_then_die
                return getattr(outer.store, name)

        return Proxy()

    def restart_empty(self) -> None:
        self.store = open_store("memory")


def test_state_file_round_trip_and_atomic_replacement(tmp_path) -> None:
    state = AnchoringStateFile(tmp_path / "state")
    assert state.load().snapshot is None  # a first run
    state.save_symbols({"cup": 3})
    state.save_anchors({"format": "x", "anchors": []}, frozenset({"cup_1"}))
    loaded = state.load()
    assert (loaded.symbol_indices, loaded.owned_objects) == ({"cup": 3}, frozenset({"cup_1"}))
    assert sorted(path.name for path in (tmp_path / "state").iterdir()) == ["anchors.json", "symbols.json"]


def test_a_damaged_state_file_is_a_clear_error(tmp_path) -> None:
    state = AnchoringStateFile(tmp_path)
    (tmp_path / "anchors.json").write_text("{truncated")
    with pytest.raises(ConfigurationError, match="damaged"):
        state.load()
    (tmp_path / "anchors.json").write_text(json.dumps({"format": 99}))
    with pytest.raises(ConfigurationError, match="format"):
        state.load()


def test_views_are_frozen_copies() -> None:
    live = anchor("cup_1", 1.0)
    (view,) = views_of([live])
    live.position[0] = 5.0
    assert isinstance(view, AnchorView) and view.position[0] == 1.0
    with pytest.raises(ValueError):
        view.position[0] = 2.0


def test_worker_keeps_anchors_through_an_outage_and_fills_a_restarted_knowledge_base(tmp_path) -> None:
    anchors = [anchor("cup_1", 1.0)]
    copy = lambda: AnchorsCopy(views_of(anchors), lambda: {"anchors": [a.symbol for a in anchors]})  # noqa: E731
    kb, logs = FlakyStore(), []
    worker = PersistenceWorker(copy, AnchoringStateFile(tmp_path), kb.open, GROUNDING,
                               log=lambda level, message: logs.append((level, message)))
    worker.step()
    assert kb.store.objects.get("cup_1") is not None

    kb.down = True
    anchors.append(anchor("book_1", 1.2))
    worker.step()
    worker.step()
    assert [level for level, _ in logs] == ["error"]  # said once, not every period
    assert "anchors are kept" in logs[0][1]

    kb.restart_empty()  # it came back, having lost everything
    kb.down = False
    worker.step()
    assert {o.name for o in kb.store.objects.get_all()} >= {"cup_1", "book_1"}
    assert logs[-1][0] == "info"
    assert worker.owned_objects >= {"cup_1", "book_1"}


def test_stop_saves_the_anchors_even_when_the_knowledge_base_breaks_unexpectedly(tmp_path) -> None:
    def broken_knowledge_base():
        raise RuntimeError("a bug somewhere below")

    state = AnchoringStateFile(tmp_path)
    logs = []
    worker = PersistenceWorker(lambda: AnchorsCopy(views_of([anchor("cup_1", 1.0)]), lambda: {"anchors": ["cup_1"]}),
                               state, broken_knowledge_base, GROUNDING,
                               log=lambda level, message: logs.append(level))
    worker.stop()
    assert state.load().snapshot == {"anchors": ["cup_1"]}
    assert "error" in logs


def test_a_sync_that_creates_objects_saves_the_state_at_once(tmp_path) -> None:
    """A crash right after the knowledge base got a new object must not orphan it."""
    kb = FlakyStore()
    anchors = [anchor("cup_1", 1.0)]
    state = AnchoringStateFile(tmp_path)
    worker = PersistenceWorker(lambda: AnchorsCopy(views_of(anchors), lambda: {"anchors": [a.symbol for a in anchors]}),
                               state, kb.open, GROUNDING, save_period=3600.0)
    worker.step()  # the first step is due anyway
    anchors.append(anchor("book_1", 1.2))
    worker.step()  # long before the next periodic save
    assert "book_1" in state.load().owned_objects
    worker.step()  # nothing new: no save needed (and none made: the file is unchanged)
    assert len(state.load().snapshot["anchors"]) == 2


class Killed(BaseException):
    """The process dying: no code of the worker runs after it."""


def test_a_node_killed_while_the_knowledge_base_applies_a_new_object_restarts_owning_it(tmp_path) -> None:
    """Write-ahead: the state file claims an object before the batch that creates it is sent, so a
    kill at any moment of that batch leaves no object in the knowledge base that nobody owns."""
    kb = FlakyStore()
    anchors = [anchor("cup_1", 1.0)]
    state = AnchoringStateFile(tmp_path)
    copy = lambda: AnchorsCopy(views_of(anchors), lambda: {"anchors": [a.symbol for a in anchors]})  # noqa: E731
    worker = PersistenceWorker(copy, state, kb.open, GROUNDING, save_period=3600.0)
    worker.step()
    anchors.append(anchor("book_1", 1.2))
    real_apply = kb.store.apply

    def apply_then_killed(changes):
        real_apply(changes)
        raise Killed

    kb.store.apply = apply_then_killed
    with pytest.raises(Killed):
        worker.step()
    kb.store.apply = real_apply
    assert kb.store.objects.get("book_1") is not None  # the knowledge base has it; the node died
    saved = state.load()
    assert saved.snapshot == {"anchors": ["cup_1", "book_1"]} and "book_1" in saved.owned_objects
    restarted = PersistenceWorker(copy, state, kb.open, GROUNDING, owned_objects=saved.owned_objects)
    restarted.step()
    assert restarted.owned_objects == {"cup_1", "book_1"}
    anchors.pop()  # book_1 forgotten after the restart: its object goes with it
    restarted.step()
    assert kb.store.objects.get("book_1") is None


def test_objects_created_by_a_batch_whose_answer_was_lost_stay_ours(tmp_path) -> None:
    """A knowledge base killed after committing a batch, before answering: its objects are still
    the anchors' own, saved as such, and deleted with their anchor later (none left behind)."""
    kb = FlakyStore()
    anchors = [anchor("cup_1", 1.0)]
    state = AnchoringStateFile(tmp_path)
    worker = PersistenceWorker(lambda: AnchorsCopy(views_of(anchors), lambda: {"anchors": [a.symbol for a in anchors]}),
                               state, kb.open, GROUNDING, save_period=3600.0)
    worker.step()
    anchors.append(anchor("book_1", 1.2))
    kb.answers_lost = True
    worker.step()
    assert kb.store.objects.get("book_1") is not None  # committed, but the worker never heard so
    assert "book_1" in state.load().owned_objects  # a node restarted now would adopt it
    kb.answers_lost = False
    worker.step()  # the rebuilt sync finds book_1 in the store
    assert worker.owned_objects == {"cup_1", "book_1"}
    assert state.load().owned_objects == {"cup_1", "book_1"}
    anchors.pop()  # book_1 forgotten
    worker.step()
    assert kb.store.objects.get("book_1") is None
    assert [o.name for o in kb.store.objects.get_all() if o.name in ("cup_1", "book_1")] == ["cup_1"]
