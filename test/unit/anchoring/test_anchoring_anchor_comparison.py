"""Anchor against anchor: a candidate is scored over all its views, never by its luckiest one."""

from __future__ import annotations

import numpy as np
import pytest

from merlin2_sailor.anchoring.anchor import Anchor
from merlin2_sailor.anchoring.anchor_comparison import SearchedDisc, identity_scores, looks_compared
from merlin2_sailor.anchoring.features import FeatureConfig, PairFeatures
from merlin2_sailor.anchoring.fusion import FusionConfig
from merlin2_sailor.anchoring.gallery import to_bfloat16_bits
from merlin2_sailor.anchoring.matcher import Matcher
from merlin2_sailor.anchoring.rule_matcher import RuleMatcher
from merlin2_sailor.contract.percept import BoundingBox2D, Percept


class AppearanceOnly(Matcher):
    """1 for a view identical to the lost anchor's nearest one, falling with the L1 distance;
    records the distances it was asked about."""

    uses_appearance = True

    def __init__(self) -> None:
        self.distances: list[np.ndarray] = []

    @property
    def feature_config(self) -> FeatureConfig:
        return FeatureConfig()

    def score_pairs(self, features: PairFeatures) -> np.ndarray:
        self.distances.append(features.distance)
        return np.exp(-features.appearance_distance)


def anchor(symbol: str, views: list[list[float]], position=(0.0, 0.0, 0.8), stamp: float = 0.0) -> Anchor:
    percept = Percept(class_name="cup", score=0.9, box=BoundingBox2D(50.0, 50.0, 20.0, 20.0),
                      position=np.asarray(position, dtype=float), size=np.full(3, 0.1), stamp=stamp)
    made = Anchor.from_percept(symbol, percept, None, FusionConfig())
    made.gallery = to_bfloat16_bits(np.asarray(views, dtype=np.float32))
    return made


def test_a_candidate_scores_the_mean_of_its_views_not_its_best():
    lost = anchor("cup_1", [[1.0, 0.0, 0.0, 0.0]])
    lucky = anchor("cup_2", [[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 4.0, 0.0], [0.0, 0.0, 0.0, 4.0]], stamp=5.0)
    steady = anchor("cup_3", [[1.0, 0.5, 0.0, 0.0], [1.0, 0.0, 0.5, 0.0]], stamp=5.0)
    scores = identity_scores(AppearanceOnly(), [lucky, steady], lost)
    # lucky: one identical view (1.0) and two far ones (exp(-5)); steady: two views 0.5 away.
    assert scores[0] == pytest.approx((1.0 + 2 * np.exp(-5.0)) / 3, rel=1e-3)
    assert scores[1] == pytest.approx(np.exp(-0.5), rel=1e-2)
    assert scores[1] > scores[0]


def test_a_search_measures_the_lost_anchor_from_the_searched_disc():
    lost = anchor("cup_1", [[1.0, 0.0]], position=(0.0, 0.0, 0.8))
    candidate = anchor("cup_2", [[1.0, 0.0]], position=(5.0, 0.0, 0.8), stamp=5.0)
    matcher = AppearanceOnly()
    identity_scores(matcher, [candidate], lost)
    identity_scores(matcher, [candidate], lost, SearchedDisc(np.array([5.5, 0.0, 0.8]), 1.0))
    assert matcher.distances[0][0] == pytest.approx(5.0) and matcher.distances[1][0] == pytest.approx(0.0)


def test_no_candidates_give_no_scores():
    assert identity_scores(AppearanceOnly(), [], anchor("cup_1", [[1.0]])).shape == (0,)


class TimeOnly(Matcher):
    """The time feature alone: how the gap between the candidate's first sighting and the lost
    anchor's last one is measured."""

    uses_appearance = False

    @property
    def feature_config(self) -> FeatureConfig:
        return FeatureConfig()

    def score_pairs(self, features: PairFeatures) -> np.ndarray:
        return features.time_difference


def test_a_lost_anchor_is_last_seen_when_it_went_missing_not_at_a_sighting_while_missing():
    """A sighting while missing, too few to bring it back (perhaps of the candidate itself), does
    not make the candidate seem seen before the lost object was."""
    from merlin2_sailor.anchoring.anchor import AnchorState

    lost = anchor("cup_1", [[1.0, 0.0]], stamp=100.0)
    candidate = anchor("cup_2", [[1.0, 0.0]], stamp=160.0)
    lost.state, lost.lost_after, lost.last_seen = AnchorState.MISSING, 100.0, 300.0
    for disc in (None, SearchedDisc(np.zeros(3), 3.0)):
        assert identity_scores(TimeOnly(), [candidate], lost, disc) == pytest.approx([60.0])
    lost.lost_after = None  # back, or never lost: its latest sighting is its last
    assert identity_scores(TimeOnly(), [candidate], lost) == pytest.approx([-140.0])


def sized(made: Anchor, sizes: list[float]) -> Anchor:
    made.gallery_scales = np.asarray(sizes, dtype=np.float32)
    return made


@pytest.mark.parametrize(("lost_sizes", "candidate_sizes", "counted"), [
    ([48.0, 61.0], [10.0, 18.0, 60.0], [False, False, True]),  # the far views of a new anchor: left out
    ([48.0, 61.0], [23.0, 23.9, 60.0], [False, False, True]),  # just under half the smallest
    ([48.0, 61.0], [24.0, 40.0, 60.0], [True, True, True]),  # half the smallest and over: counted
    ([20.0, 22.0], [9.0, 18.0, 60.0], [False, True, True]),  # a lost anchor seen only from afar
    ([48.0, 61.0], [10.0, 18.0, 20.0], [True, True, True]),  # no view comparable: every view counts
    ([48.0, float("nan")], [10.0, 60.0], [True, True]),  # the lost anchor's sizes unknown
    ([48.0, 61.0], [float("nan"), 60.0], [True, True]),  # a view of unknown size counts
])
def test_views_too_far_to_tell_from_the_lost_anchors_are_left_out_of_the_mean(lost_sizes, candidate_sizes, counted):
    views = [[0.0, 0.0, 3.0 * k, 0.0] for k in range(len(candidate_sizes))]  # view k: 3k away
    lost = sized(anchor("cup_1", [[0.0, 0.0, 0.0, 0.0]] * len(lost_sizes)), lost_sizes)
    candidate = sized(anchor("cup_2", views, stamp=5.0), candidate_sizes)
    per_view = np.exp(-3.0 * np.arange(len(candidate_sizes)))
    expected = per_view[np.asarray(counted)].mean()
    scores = identity_scores(AppearanceOnly(), [candidate], lost, far_view_ratio=0.5)
    assert scores == pytest.approx([expected], rel=1e-2)
    # Off (0), every view counts, as before.
    assert identity_scores(AppearanceOnly(), [candidate], lost) == pytest.approx([per_view.mean()], rel=1e-2)


def test_each_candidate_keeps_its_own_views_when_several_are_scored_at_once():
    lost = sized(anchor("cup_1", [[0.0, 0.0]]), [50.0])
    near_and_far = sized(anchor("cup_2", [[0.0, 0.0], [0.0, 3.0]], stamp=5.0), [60.0, 10.0])
    only_far = sized(anchor("cup_3", [[0.0, 1.0], [0.0, 3.0]], stamp=5.0), [10.0, 12.0])
    scores = identity_scores(AppearanceOnly(), [near_and_far, only_far], lost, far_view_ratio=0.5)
    assert scores == pytest.approx([1.0, (np.exp(-1.0) + np.exp(-3.0)) / 2], rel=1e-2)


def test_a_matcher_without_appearance_scores_as_before():
    """The rules keep no gallery and read no look: leaving far views out changes nothing for them."""
    from merlin2_sailor.anchoring.rule_matcher import RuleMatcher
    lost = sized(anchor("cup_1", [[0.0, 0.0], [0.0, 0.0]]), [48.0, 61.0])
    candidates = [sized(anchor("cup_2", [[0.0, 3.0], [0.0, 0.0]], position=(0.4, 0.0, 0.8), stamp=5.0), [10.0, 60.0]),
                  sized(anchor("cup_3", [[0.0, 3.0]], position=(1.5, 0.0, 0.8), stamp=30.0), [9.0])]
    for disc in (None, SearchedDisc(np.array([1.0, 0.0, 0.8]), 2.0)):
        before = identity_scores(RuleMatcher(), candidates, lost, disc)
        assert identity_scores(RuleMatcher(), candidates, lost, disc, far_view_ratio=0.5) == pytest.approx(before)
        assert (before > 0.0).all()


def test_a_look_is_compared_only_where_both_have_views_of_one_extent_and_the_matcher_reads_looks():
    """:func:`looks_compared` says which scores read the candidate's look: none for a matcher without
    appearance, none for a candidate or lost anchor without views, none for a view of a part of the
    lost object (a bicycle's end seen through a door), the rest yes."""
    lost = anchor("bicycle_1", [[1.0, 0.0]])
    lost.size, lost.whole_views = np.array([0.35, 1.6, 1.0]), 10
    whole = anchor("bicycle_2", [[1.0, 0.0]], stamp=5.0)
    whole.size = np.array([0.36, 1.55, 0.98])
    part = anchor("bicycle_3", [[1.0, 0.0]], stamp=5.0)
    part.size = np.array([0.36, 0.2, 0.98])
    no_views = anchor("bicycle_4", [[1.0, 0.0]], stamp=5.0)
    no_views.size = whole.size.copy()
    no_views.gallery = None
    candidates = [whole, part, no_views]
    assert looks_compared(AppearanceOnly(), candidates, lost).tolist() == [True, False, False]
    assert looks_compared(RuleMatcher(), candidates, lost).tolist() == [False, False, False]
    blind = anchor("bicycle_1", [[1.0, 0.0]])
    blind.size, blind.whole_views, blind.gallery = lost.size, lost.whole_views, None
    assert looks_compared(AppearanceOnly(), candidates, blind).tolist() == [False, False, False]
