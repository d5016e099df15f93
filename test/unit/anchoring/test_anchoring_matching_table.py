"""The matching table: spatial gating, class gating, tracker shortcut, embedding at most once."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from merlin2_sailor.anchoring import (
    AnchorIndex,
    AnchorState,
    FusionConfig,
    MatchingTableBuilder,
    MatchingTableConfig,
    RuleMatcher,
)
from merlin2_sailor.anchoring.anchor import Anchor
from merlin2_sailor.anchoring.features import PairFeatures
from merlin2_sailor.errors import ConfigurationError

from .anchoring_scenes import SceneObject

CUP = SceneObject("cup", "cup", (2.0, 0.0, 0.8))
CROP = np.full((8, 8, 3), 128, dtype=np.uint8)


class CountingMatcher(RuleMatcher):
    """The rule matcher, recording how many pairs it was asked to score."""

    def __init__(self, uses_appearance: bool = False) -> None:
        super().__init__()
        self.uses_appearance = uses_appearance
        self.scored_pairs: list[int] = []

    def score_pairs(self, features: PairFeatures) -> np.ndarray:
        self.scored_pairs.append(len(features))
        return super().score_pairs(features)


class CountingEmbedder:
    """Embeds a crop as its mean colour repeated; records each call's batch size."""

    def __init__(self, dimension: int = 32) -> None:
        self.dimension = dimension
        self.calls: list[int] = []

    def embed(self, crops):
        self.calls.append(len(crops))
        return np.array([np.full(self.dimension, crop.mean() / 255.0) for crop in crops], dtype=np.float32)


def index_of(*anchors):
    index = AnchorIndex()
    for anchor in anchors:
        index.add(anchor)
    return index


def anchor_of(maker, item, symbol, stamp=0.0, tracker_id="", state=AnchorState.CONFIRMED, embedding=True):
    percept = maker.percept(item, stamp, tracker_id=tracker_id)
    anchor = Anchor.from_percept(symbol, percept, percept.embedding if embedding else None, FusionConfig())
    anchor.state = state
    return anchor


def moved(item, offset, class_name=None):
    return SceneObject(item.identity, class_name or item.class_name, tuple(np.asarray(item.position) + offset))


def test_anchors_beyond_the_base_gate_are_gated(maker):
    near = anchor_of(maker, CUP, "cup_1", stamp=10.0)
    far = anchor_of(maker, moved(CUP, (0.0, 3.5, 0.0)), "cup_2", stamp=10.0)
    table = MatchingTableBuilder(RuleMatcher()).build([maker.percept(CUP, 10.0)], index_of(near, far))
    assert [a.symbol for a in table.anchors] == ["cup_1"]  # the far one is not even a column


def test_the_gate_grows_with_time_unseen_up_to_its_cap(maker):
    config = MatchingTableConfig(base_gate=3.0, maximum_speed=0.25, maximum_gate=8.0)
    builder = MatchingTableBuilder(RuleMatcher(), config)
    np.testing.assert_allclose(builder.gate_radius(np.array([-1.0, 0.0, 10.0, 1000.0])), [3.0, 3.0, 5.5, 8.0])
    recent = anchor_of(maker, moved(CUP, (0.0, 5.0, 0.0)), "cup_1", stamp=99.0)
    stale = anchor_of(maker, moved(CUP, (0.0, -5.0, 0.0)), "cup_2", stamp=90.0)
    ancient = anchor_of(maker, moved(CUP, (9.0, 0.0, 0.0)), "cup_3", stamp=0.0)
    table = builder.build([maker.percept(CUP, 100.0)], index_of(recent, stale, ancient))
    ungated = {a.symbol for a, gated in zip(table.anchors, table.gated[0], strict=True) if not gated}
    assert ungated == {"cup_2"}  # 5 m: beyond 3.25 m for cup_1, within 5.5 m for cup_2; 9 m > 8 m cap


def test_class_mismatch_is_gated_when_configured(maker):
    bowl = anchor_of(maker, moved(CUP, (0.1, 0.0, 0.0), "bowl"), "bowl_1")
    percepts = [maker.percept(CUP, 0.1)]
    gated = MatchingTableBuilder(RuleMatcher()).build(percepts, index_of(bowl))
    assert gated.gated.all() and np.all(gated.scores == MatchingTableConfig().gated_score)
    open_table = MatchingTableBuilder(RuleMatcher(), MatchingTableConfig(gate_class_mismatch=False)).build(
        percepts, index_of(bowl)
    )
    assert not open_table.gated.any() and open_table.scores[0, 0] == 0.0  # scored, and M says no


def test_far_anchors_cost_nothing(maker):
    rng = np.random.default_rng(0)
    far = [
        anchor_of(maker, SceneObject("x", "cup", tuple(rng.uniform(50, 100, 3))), f"cup_{n}") for n in range(500)
    ]
    matcher = CountingMatcher()
    table = MatchingTableBuilder(matcher).build([maker.percept(CUP, 0.1)], index_of(*far))
    assert table.anchors == () and table.scores.shape == (1, 0)
    assert matcher.scored_pairs == []


def test_only_ungated_pairs_reach_the_matcher(maker):
    anchors = [anchor_of(maker, moved(CUP, (0.0, 0.45 * n, 0.0)), f"cup_{n}") for n in range(10)]
    anchors += [anchor_of(maker, moved(CUP, (0.0, 0.5 * n, 0.0), "bowl"), f"bowl_{n}") for n in range(10)]
    matcher = CountingMatcher()
    table = MatchingTableBuilder(matcher).build([maker.percept(CUP, 0.0)], index_of(*anchors))
    assert matcher.scored_pairs == [int((~table.gated).sum())]
    assert int((~table.gated).sum()) == 7  # cups at 0 .. 2.7 m (3.15 m is beyond); bowls gated by class


def test_tracker_continuation_skips_scoring_and_embedding(maker):
    continued = anchor_of(maker, CUP, "cup_1", stamp=0.0, tracker_id="5", embedding=False)
    neighbour = anchor_of(maker, moved(CUP, (0.0, 0.3, 0.0)), "cup_2", stamp=0.0)
    percept = dataclasses.replace(maker.percept(CUP, 0.1, tracker_id="5", with_embedding=False), crop=CROP)
    matcher, embedder = CountingMatcher(uses_appearance=True), CountingEmbedder()
    table = MatchingTableBuilder(matcher, embedder=embedder).build([percept], index_of(continued, neighbour))
    assert table.shortcut.tolist() == [True]
    assert embedder.calls == [] and matcher.scored_pairs == [] and table.embedded == 0
    row = dict(zip([a.symbol for a in table.anchors], table.scores[0], strict=True))
    assert row == {"cup_1": MatchingTableConfig().tracker_continuity_score, "cup_2": MatchingTableConfig().gated_score}


@pytest.mark.parametrize(("other_offset", "may_take_it"), [(0.09, False), (0.3, False), (0.0, True)])
def test_a_continued_anchor_is_claimed_from_views_no_nearer_to_it(maker, other_offset, may_take_it):
    # The continued view stands 0.02 m from its anchor; another view of the class without the id
    # may take the anchor only when it stands nearer (the tracker may have handed the id on).
    continued = anchor_of(maker, CUP, "cup_1", stamp=0.0, tracker_id="5")
    view = maker.percept(moved(CUP, (0.02, 0.0, 0.0)), 0.1, tracker_id="5")
    other = maker.percept(moved(CUP, (0.0, other_offset, 0.0)), 0.1, tracker_id="8")
    table = MatchingTableBuilder(RuleMatcher()).build([view, other], index_of(continued))
    assert table.shortcut.tolist() == [True, False]
    assert table.gated[1, 0] == (not may_take_it)


@pytest.mark.parametrize(
    ("state", "age", "class_name", "tracker_id"),
    [
        (AnchorState.TENTATIVE, 0.1, "cup", "5"),  # not confirmed
        (AnchorState.CONFIRMED, 5.0, "cup", "5"),  # too old
        (AnchorState.CONFIRMED, 0.1, "bowl", "5"),  # class mismatch
        (AnchorState.CONFIRMED, 0.1, "cup", ""),  # no id
    ],
)
def test_no_shortcut_without_a_clear_continuation(maker, state, age, class_name, tracker_id):
    anchor = anchor_of(maker, CUP, "cup_1", stamp=0.0, tracker_id=tracker_id, state=state)
    percept = dataclasses.replace(
        maker.percept(CUP, age, tracker_id=tracker_id, class_name=class_name, with_embedding=False), crop=CROP
    )
    embedder = CountingEmbedder()
    config = MatchingTableConfig(gate_class_mismatch=False)
    builder = MatchingTableBuilder(CountingMatcher(uses_appearance=True), config, embedder)
    table = builder.build([percept], index_of(anchor))
    assert table.shortcut.tolist() == [False]
    assert embedder.calls == [1]
    if class_name != "cup":
        assert table.scores[0, 0] == 0.0  # the continuing id did not raise a class mismatch


def test_two_anchors_continuing_one_id_are_no_shortcut(maker):
    first = anchor_of(maker, CUP, "cup_1", tracker_id="5")
    second = anchor_of(maker, moved(CUP, (0.0, 0.05, 0.0)), "cup_2", tracker_id="5")
    percept = maker.percept(CUP, 0.1, tracker_id="5")
    table = MatchingTableBuilder(RuleMatcher()).build([percept], index_of(first, second))
    assert table.shortcut.tolist() == [False]
    assert np.all(table.scores[0] >= MatchingTableConfig().tracker_continuity_score)  # both raised to the floor


def test_an_id_that_swapped_to_a_neighbour_does_not_pull_the_percept_off_its_own_anchor(maker):
    """Books 0.3 m apart on a shelf: the tracker gave book B's percept the id of book A's anchor."""
    book_a = anchor_of(maker, moved(CUP, (0.0, 0.3, 0.0)), "cup_1", tracker_id="7")
    book_b = anchor_of(maker, CUP, "cup_2", tracker_id="8")
    percept_of_b = maker.percept(CUP, 0.1, tracker_id="7")
    table = MatchingTableBuilder(RuleMatcher()).build([percept_of_b], index_of(book_a, book_b))
    assert table.shortcut.tolist() == [False] and not table.continuations.any()
    column = {anchor.symbol: index for index, anchor in enumerate(table.anchors)}
    assert table.scores[0, column["cup_2"]] > table.scores[0, column["cup_1"]]


def test_each_crop_is_embedded_once_in_one_call(maker):
    anchors = [anchor_of(maker, moved(CUP, (0.0, 0.4 * n, 0.0)), f"cup_{n}") for n in range(3)]
    with_crop = [
        dataclasses.replace(maker.percept(moved(CUP, (0.0, 0.4 * n, 0.0)), 0.1, with_embedding=False), crop=CROP)
        for n in range(3)
    ]
    already_embedded = maker.percept(CUP, 0.1)
    without_crop = maker.percept(CUP, 0.1, with_embedding=False)
    far_away = dataclasses.replace(maker.percept(moved(CUP, (30.0, 0.0, 0.0)), 0.1, with_embedding=False), crop=CROP)
    embedder = CountingEmbedder()
    table = MatchingTableBuilder(CountingMatcher(uses_appearance=True), embedder=embedder).build(
        [*with_crop, already_embedded, without_crop, far_away], index_of(*anchors)
    )
    assert embedder.calls == [3] and table.embedded == 3
    assert all(p.embedding is not None for p in table.percepts[:4])
    assert table.percepts[3] is already_embedded
    assert table.percepts[4].embedding is None and table.percepts[5].embedding is None  # no crop / nothing to match


def test_a_rule_matcher_never_triggers_embedding(maker):
    embedder = CountingEmbedder()
    percept = dataclasses.replace(maker.percept(CUP, 0.1, with_embedding=False), crop=CROP)
    MatchingTableBuilder(RuleMatcher(), embedder=embedder).build([percept], index_of(anchor_of(maker, CUP, "cup_1")))
    assert embedder.calls == []


@pytest.mark.parametrize(
    "options",
    [
        {"base_gate": 0.0},
        {"maximum_speed": -1.0},
        {"maximum_gate": 1.0},
        {"tracker_continuity_score": 1.5},
        {"continuation_maximum_age": -1.0},
        {"gated_score": 0.0},
    ],
)
def test_table_configuration_is_validated(options):
    with pytest.raises(ConfigurationError, match=next(iter(options))):
        MatchingTableConfig(**options)
