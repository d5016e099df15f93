"""The rule matcher: class, distance and time; and the Matcher interface's (P, A) table."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from merlin2_sailor.anchoring import AnchorEvent, AnchorEventKind, FusionConfig, RuleMatcher, RuleMatcherConfig
from merlin2_sailor.anchoring.anchor import Anchor
from merlin2_sailor.errors import ConfigurationError

from .anchoring_scenes import KITCHEN, SceneObject


def anchor_at(maker, item, stamp=0.0):
    return Anchor.from_percept(f"{item.class_name}_1", maker.percept(item, stamp), None, FusionConfig())


def exact(maker, item, stamp, offset=(0.0, 0.0, 0.0), class_name=None):
    """A percept exactly ``offset`` from the object's true position (no position noise)."""
    percept = maker.percept(item, stamp, class_name=class_name)
    return dataclasses.replace(percept, position=np.asarray(item.position, dtype=np.float64) + offset)


def test_score_is_one_half_at_the_documented_distance(maker):
    item = SceneObject("cup", "cup", (1.0, 0.0, 0.8))
    anchor = anchor_at(maker, item)
    anchor.position = np.asarray(item.position, dtype=np.float64)
    sigma = RuleMatcherConfig().position_sigma
    half_distance = sigma * math.sqrt(2.0 * math.log(2.0))
    scores = RuleMatcher().score(
        [exact(maker, item, 0.0), exact(maker, item, 0.0, (half_distance, 0, 0)), exact(maker, item, 0.0, (1.0, 0, 0))],
        [anchor],
    )
    np.testing.assert_allclose(scores[:, 0], [1.0, 0.5, math.exp(-0.5 / sigma**2)], rtol=1e-9)


def test_different_classes_never_match(maker):
    item = KITCHEN[0]
    assert RuleMatcher().score([exact(maker, item, 0.0, class_name="bowl")], [anchor_at(maker, item)])[0, 0] == 0.0


def test_tolerance_widens_with_time_up_to_a_cap(maker):
    item = SceneObject("cup", "cup", (1.0, 0.0, 0.8))
    anchor = anchor_at(maker, item)
    anchor.position = np.asarray(item.position, dtype=np.float64)
    matcher = RuleMatcher(RuleMatcherConfig(position_sigma=0.3, drift_speed=0.1, maximum_sigma=1.0))
    offset = (0.6, 0.0, 0.0)
    fresh, later, much_later, ages_later = (
        matcher.score([exact(maker, item, stamp, offset)], [anchor])[0, 0] for stamp in (0.0, 3.0, 7.0, 1000.0)
    )
    assert fresh < later < much_later
    assert much_later == pytest.approx(ages_later)  # sigma capped at 1 m from 7 s on


def test_table_shape_and_order(maker):
    anchors = [anchor_at(maker, item) for item in KITCHEN]
    percepts = [maker.percept(item, 0.1) for item in reversed(KITCHEN)]
    table = RuleMatcher().score(percepts, anchors)
    assert table.shape == (3, 3)
    assert np.argmax(table, axis=1).tolist() == [2, 1, 0]
    assert RuleMatcher().score([], anchors).shape == (0, 3) and RuleMatcher().score(percepts, []).shape == (3, 0)


@pytest.mark.parametrize(
    "options",
    [
        {"position_sigma": 0.0},
        {"drift_speed": -0.1},
        {"maximum_sigma": math.inf},
        {"position_sigma": 2.0, "maximum_sigma": 1.0},
    ],
)
def test_rule_configuration_is_validated(options):
    with pytest.raises(ConfigurationError):
        RuleMatcherConfig(**options)


def test_event_details_are_frozen_copies():
    details = {"reason": "seen"}
    event = AnchorEvent(AnchorEventKind.CONFIRMED, "cup_1", 1.0, details)
    details["reason"] = "changed"
    assert event.details["reason"] == "seen"
    with pytest.raises(TypeError):
        event.details["reason"] = "x"  # type: ignore[index]
