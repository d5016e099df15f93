"""The anchor index: exact radius queries over a loosely maintained k-d tree."""

from __future__ import annotations

import numpy as np
import pytest

from merlin2_sailor.anchoring import AnchorIndex, IndexConfig
from merlin2_sailor.anchoring.anchor import Anchor
from merlin2_sailor.errors import ConfigurationError, InvalidInputError


def anchor_at(symbol, position, last_seen=0.0):
    position = np.asarray(position, dtype=np.float64)
    return Anchor(symbol, "cup", position, np.full(3, 0.1), 0.0, last_seen, perceived_position=position.copy())


def brute_force(anchors, point, radius):
    return sorted(a.symbol for a in anchors if np.linalg.norm(a.position - point) <= radius)


def found(index, point, radius):
    return sorted(a.symbol for a in index.anchors_at(index.within(np.asarray(point).reshape(1, 3), radius)[0]))


def test_queries_match_brute_force_through_adds_moves_and_removals():
    rng = np.random.default_rng(3)
    index = AnchorIndex(IndexConfig(tolerance=0.2, rebuild_minimum=8, rebuild_fraction=0.05))
    anchors = {}
    for number in range(300):
        anchor = anchor_at(f"cup_{number}", rng.uniform(-10, 10, 3))
        anchors[anchor.symbol] = anchor
        index.add(anchor)
    for step in range(200):
        symbol = f"cup_{rng.integers(300)}"
        if symbol in anchors and step % 5 == 0:
            index.remove(symbol)
            del anchors[symbol]
        elif symbol in anchors:
            anchor = anchors[symbol]
            anchor.position = anchor.position + rng.normal(scale=0.3 if step % 2 else 0.05, size=3)
            index.refresh(anchor)
        point = rng.uniform(-10, 10, 3)
        radius = float(rng.uniform(0.5, 4.0))
        assert found(index, point, radius) == brute_force(anchors.values(), point, radius), step
    assert len(index) == len(anchors)


def test_oldest_last_seen_and_membership():
    index = AnchorIndex()
    assert index.oldest_last_seen() == np.inf
    index.add(anchor_at("cup_1", (0, 0, 0), last_seen=5.0))
    index.add(anchor_at("cup_2", (1, 0, 0), last_seen=2.0))
    assert index.oldest_last_seen() == 2.0
    index.remove("cup_2")
    assert index.oldest_last_seen() == 5.0
    assert "cup_1" in index and "cup_2" not in index and index.get("cup_2") is None
    assert index.remove("cup_2") is None


def test_duplicate_symbols_and_bad_positions_are_refused():
    index = AnchorIndex()
    index.add(anchor_at("cup_1", (0, 0, 0)))
    with pytest.raises(InvalidInputError, match="cup_1"):
        index.add(anchor_at("cup_1", (1, 1, 1)))
    with pytest.raises(InvalidInputError, match="position"):
        index.add(anchor_at("cup_2", (np.nan, 0, 0)))


def test_slots_are_reused_after_removal():
    index = AnchorIndex()
    for number in range(20):
        index.add(anchor_at(f"cup_{number}", (number, 0, 0)))
    index.rebuild()
    index.remove("cup_3")
    index.add(anchor_at("bowl_1", (100.0, 0, 0)))
    assert found(index, (3.0, 0, 0), 0.5) == []
    assert found(index, (100.0, 0, 0), 0.5) == ["bowl_1"]


def test_index_configuration_is_validated():
    with pytest.raises(ConfigurationError, match="tolerance"):
        IndexConfig(tolerance=-1.0)
    with pytest.raises(ConfigurationError, match="rebuild_fraction"):
        IndexConfig(rebuild_fraction=0.0)
