"""Scoring matchers on a tour: the same frames for each, and counts that can tell a bad one."""

from __future__ import annotations

import numpy as np

from merlin2_sailor.anchoring.features import FeatureConfig, PairFeatures
from merlin2_sailor.anchoring.matcher import Matcher
from merlin2_sailor.anchoring.rule_matcher import RuleMatcher, RuleMatcherConfig
from merlin2_sailor_demos.identity.generated_houses import generated_world
from merlin2_sailor_demos.identity.tour import TourConfig
from merlin2_sailor_demos.identity.tour_evaluation import MatcherSetup, evaluate_tour, format_tour_table

from .conftest import SMALL_HOUSES


class NeverTheSame(Matcher):
    """Says every pair is two objects: each sighting the tracker cannot continue is a new anchor."""

    @property
    def feature_config(self) -> FeatureConfig:
        return FeatureConfig()

    def score_pairs(self, features: PairFeatures) -> np.ndarray:
        return np.zeros(len(features))


def test_rules_keep_one_anchor_per_object_and_a_matcher_that_never_matches_does_not() -> None:
    description = generated_world(np.random.default_rng(7), SMALL_HOUSES)
    seen_frames = []

    class Watcher:
        def before(self, frame, anchorings) -> None:  # noqa: ANN001
            seen_frames.append((frame.stamp, sorted(anchorings)))

        def after(self, frame, results) -> None:  # noqa: ANN001
            assert sorted(results) == ["never", "rules"]

    scores = evaluate_tour(
        description,
        {"rules": lambda: MatcherSetup(RuleMatcher(RuleMatcherConfig(maximum_sigma=0.3))),
         "never": lambda: MatcherSetup(NeverTheSame())},
        seed=0, tour=TourConfig(rate_hz=5.0), observer=Watcher(),
    )
    assert seen_frames and all(names == ["never", "rules"] for _, names in seen_frames)
    rules, never = scores["rules"], scores["never"]
    assert rules.scorecard.anchored >= 0.8 * rules.scorecard.objects
    assert rules.duplicates <= 1 and not rules.merged_symbols
    assert never.duplicates > rules.duplicates + 2
    assert len(never.split_objects) > len(rules.split_objects) + 2
    table = format_tour_table(scores)
    assert table.splitlines()[0].split()[:3] == ["anchored", "duplicates", "ID"]
    assert "never:" in table
