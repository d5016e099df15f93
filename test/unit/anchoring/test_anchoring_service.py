"""The ROS-free anchoring service: built from settings, its symbols and anchors survive a restart,
its anchors reach the knowledge base, and other threads read frozen views only."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from merlin2_sailor.anchoring.anchor import AnchorState
from merlin2_sailor.anchoring.rule_matcher import RuleMatcher
from merlin2_sailor.anchoring.service import AnchoringService
from merlin2_sailor.anchoring.settings import OFFLINE_OVERRIDES, settings_from_parameters
from merlin2_sailor.knowledge import open_store

from .anchoring_scenes import KITCHEN, PerceptMaker


def anchor_kitchen(service: AnchoringService, maker: PerceptMaker, frames: int, start: float = 0.0) -> None:
    for frame in range(frames):
        stamp = start + 0.1 * frame
        with service.lock:
            service.anchoring.process([maker.percept(item, stamp) for item in KITCHEN[:2]], None, stamp)


def test_the_service_is_built_as_its_settings_say() -> None:
    settings = settings_from_parameters({**OFFLINE_OVERRIDES, "matcher": "rules", "confirm_after": 5,
                                         "rules_maximum_sigma": 0.4})
    service = AnchoringService(settings)
    assert service.anchoring.config is settings.core
    assert isinstance(service.matcher, RuleMatcher) and service.matcher.config.maximum_sigma == 0.4
    assert service.embedder is None  # the rules compare no crops
    assert not service.persists  # offline: nothing leaves memory


def test_symbols_and_anchors_survive_a_restart_and_reach_the_knowledge_base(tmp_path, maker) -> None:
    settings = settings_from_parameters({  # the rules: these percepts carry synthetic embeddings
        "matcher": "rules", "state_folder": str(tmp_path / "state"), "knowledge_base": f"sqlite://{tmp_path / 'kb.db'}",
        "confirm_after": 2, "sync_period": 0.05})
    with AnchoringService(settings) as service:
        anchor_kitchen(service, maker, 3)
        symbols = sorted(view.symbol for view in service.views())
        assert len(symbols) == 2 and service.restored == 0
    # Closing saved the anchors and synced them one last time.
    with open_store(f"sqlite://{tmp_path / 'kb.db'}") as store:
        assert set(symbols) <= {item.name for item in store.objects.get_all()}  # with the map's waypoints

    restarted = AnchoringService(settings)
    try:
        assert restarted.restored == 2
        assert sorted(view.symbol for view in restarted.views()) == symbols
        with restarted.lock:  # a third object gets a fresh symbol: none is reissued
            new = restarted.anchoring.process([maker.percept(KITCHEN[2], 10.0)], None, 10.0).acquired[0]
        assert new.symbol not in symbols
        assert restarted.symbol_indices  # counters persisted with every new symbol
    finally:
        restarted.close()


def test_a_crash_between_saves_never_reissues_a_symbol(tmp_path, maker) -> None:
    settings = settings_from_parameters({"matcher": "rules", "state_folder": str(tmp_path), "knowledge_base": "",
                                         "save_period": 3600.0})
    crashed = AnchoringService(settings)  # never started nor closed: its anchors were never saved
    anchor_kitchen(crashed, maker, 1)
    handed_out = {view.symbol for view in crashed.views()}
    # The symbol counters were written with every new symbol, before it could reach anyone.
    restarted = AnchoringService(settings)
    assert restarted.restored == 0
    with restarted.lock:
        again = restarted.anchoring.process([maker.percept(item, 50.0) for item in KITCHEN[:2]], None, 50.0)
    assert len(again.acquired) == 2 and not handed_out & {anchor.symbol for anchor in again.acquired}
    restarted.close()


def test_views_taken_while_another_thread_anchors_are_consistent_copies(maker) -> None:
    service = AnchoringService(settings_from_parameters({**OFFLINE_OVERRIDES, "matcher": "rules"}))
    anchor_kitchen(service, maker, 1)
    before = {view.symbol: view for view in service.views()}
    done = threading.Event()

    def move_everything() -> None:  # the frame thread: the objects drift 1 cm per frame
        for frame in range(50):
            stamp = 1.0 + 0.1 * frame
            with service.lock:
                service.anchoring.process(
                    [maker.percept(item, stamp, position=np.add(item.position, [0.01 * frame, 0, 0]))
                     for item in KITCHEN[:2]], None, stamp)
        done.set()

    thread = threading.Thread(target=move_everything)
    thread.start()
    snapshots = []
    while not done.is_set():
        snapshots.append(service.views())
    thread.join()
    after = {view.symbol: view for view in service.views()}
    assert set(after) == set(before)
    for symbol, view in before.items():  # the first views kept what they saw
        assert view.times_seen == 1 and after[symbol].times_seen == 51
        assert after[symbol].position[0] > view.position[0] + 0.1
        with pytest.raises(ValueError):
            view.position[0] = 0.0
    for views in snapshots:  # each snapshot is one instant: both anchors fused the same frames
        assert len({view.times_seen for view in views}) == 1
    assert all(view.state in (AnchorState.TENTATIVE, AnchorState.CONFIRMED) for view in after.values())
    assert service.views_of([*before, "nothing_1"]).keys() == before.keys()
