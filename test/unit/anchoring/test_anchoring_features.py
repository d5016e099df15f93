"""Pair features: encodings, vectorisation over a table, the appearance gallery."""

from __future__ import annotations

import math

import numpy as np
import pytest

from merlin2_sailor.anchoring import FeatureConfig
from merlin2_sailor.anchoring.anchor import Anchor
from merlin2_sailor.anchoring.features import (
    MINIMUM_SEPARATION_WIDTH,
    AnchorColumns,
    PerceptColumns,
    encode_distance,
    encode_time,
    pair_features,
    scale_factor,
    separation,
)
from merlin2_sailor.anchoring.fusion import FusionConfig
from merlin2_sailor.errors import ConfigurationError, InvalidInputError

from .anchoring_scenes import KITCHEN, TWIN_MUGS


def test_distance_is_encoded_as_exp_minus_d():
    np.testing.assert_allclose(encode_distance(np.array([0.0, 1.0, 3.0])), [1.0, math.exp(-1), math.exp(-3)])


def test_time_scale_one_reproduces_the_original_encoding():
    dt = np.array([0.0, 0.5, -2.0, 5.0])
    np.testing.assert_allclose(encode_time(dt, 1.0), 2.0 / (1.0 + np.exp(np.abs(dt))))


def test_time_scale_keeps_the_time_feature_informative_beyond_seconds():
    original = encode_time(np.array([60.0, 3600.0]), 1.0)
    assert original[0] < 1e-20  # the original cannot tell a minute from an hour
    scaled = encode_time(np.array([0.0, 60.0, 3600.0]), 60.0)
    assert scaled[0] == 1.0 and 0.4 < scaled[1] < 0.6 and scaled[2] < 1e-20
    assert encode_time(np.array([1e9]), 1.0)[0] == 0.0  # no overflow warning, the right limit


def test_scale_factor_is_sum_of_minima_over_sum_of_maxima():
    assert scale_factor(np.array([1.0, 2.0, 3.0]), np.array([2.0, 2.0, 1.0])) == pytest.approx(4.0 / 7.0)
    assert scale_factor(np.array([0.1, 0.1, 0.1]), np.array([0.1, 0.1, 0.1])) == 1.0
    assert scale_factor(np.zeros(3), np.zeros(3)) == 1.0


def test_feature_config_validates_the_time_scale():
    for bad in (0.0, -1.0, math.inf, math.nan):
        with pytest.raises(ConfigurationError, match="time_scale"):
            FeatureConfig(time_scale=bad)


def anchors_from(maker, items, stamp=0.0):
    config = FusionConfig()
    return [
        Anchor.from_percept(f"{item.class_name}_{number}", maker.percept(item, stamp), None, config)
        for number, item in enumerate(items, 1)
    ]


def test_table_features_equal_pair_by_pair_features(maker):
    anchors = anchors_from(maker, KITCHEN + TWIN_MUGS)
    for anchor in anchors:  # galleries of two views
        anchor.absorb(maker.percept(next(i for i in KITCHEN + TWIN_MUGS if i.class_name == anchor.class_name), 0.5),
                      maker.appearance("red_cup") * 2.0, FusionConfig())
    percepts = [maker.percept(item, 3.0) for item in TWIN_MUGS + KITCHEN]
    config = FeatureConfig(time_scale=10.0)
    rows, columns = np.indices((len(percepts), len(anchors))).reshape(2, -1)
    percept_columns, anchor_columns = PerceptColumns.from_percepts(percepts), AnchorColumns.from_anchors(anchors)
    table = pair_features(percept_columns, anchor_columns, rows, columns, config, True)
    for k, (row, column) in enumerate(zip(rows, columns, strict=True)):
        single = pair_features(
            PerceptColumns.from_percepts([percepts[row]]),
            AnchorColumns.from_anchors([anchors[column]]),
            [0],
            [0],
            config,
            True,
        )
        assert table.same_class[k] == single.same_class[0] == (percepts[row].class_name == anchors[column].class_name)
        for name in ("distance", "distance_score", "scale", "time_difference", "time_score", "appearance_distance"):
            assert getattr(table, name)[k] == pytest.approx(getattr(single, name)[0], rel=1e-6)
        np.testing.assert_allclose(table.appearance_difference[k], single.appearance_difference[0], rtol=1e-6)
    expected = np.linalg.norm(percepts[0].position - anchors[0].position)
    assert table.distance[0] == pytest.approx(expected)
    assert table.time_difference[0] == pytest.approx(3.0 - 0.5)


def test_nearest_gallery_entry_is_compared(maker):
    side_view, front_view = maker.appearance("side"), maker.appearance("front")
    anchor = anchors_from(maker, KITCHEN[:1])[0]
    anchor.gallery = None
    for view in (side_view, front_view):
        anchor.absorb(maker.percept(KITCHEN[0], 1.0), view, FusionConfig())
    percept = maker.percept(KITCHEN[0], 2.0)
    import dataclasses

    percept = dataclasses.replace(percept, embedding=side_view + 0.05)
    features = pair_features(
        PerceptColumns.from_percepts([percept]), AnchorColumns.from_anchors([anchor]), [0], [0], FeatureConfig(), True
    )
    assert features.appearance_known[0]
    # the side view (older) is nearer than the front view (newer): it is the one compared
    assert np.abs(percept.embedding - front_view).sum() > 2 * 0.05 * len(side_view)
    assert features.appearance_distance[0] == pytest.approx(0.05 * len(side_view), rel=2e-2)
    np.testing.assert_allclose(features.appearance_difference[0], 0.05, atol=2e-3)


def test_appearance_unknown_without_embeddings(maker):
    anchor = anchors_from(maker, KITCHEN[:1])[0]
    percept = maker.percept(KITCHEN[0], 1.0, with_embedding=False)
    features = pair_features(
        PerceptColumns.from_percepts([percept]), AnchorColumns.from_anchors([anchor]), [0], [0], FeatureConfig(), True
    )
    assert not features.appearance_known[0] and math.isnan(features.appearance_distance[0])


def test_mixed_embedding_sizes_are_refused(maker):
    import dataclasses

    first = maker.percept(KITCHEN[0], 0.0)
    second = dataclasses.replace(maker.percept(KITCHEN[1], 0.0), embedding=np.zeros(5, dtype=np.float32))
    with pytest.raises(InvalidInputError, match="different sizes"):
        PerceptColumns.from_percepts([first, second])


def _columns_at(offset: float, size: tuple[float, float, float]) -> tuple[PerceptColumns, AnchorColumns]:
    """A percept ``offset`` metres along x from an anchor, both of ``size``, no appearance."""
    percepts = PerceptColumns(
        class_names=np.array(["tv"], dtype=object), positions=np.array([[offset, 0.0, 0.5]]),
        sizes=np.array([size]), stamps=np.array([1.0]), tracker_ids=np.array([""], dtype=object),
        embeddings=None, has_embedding=np.zeros(1, dtype=bool),
    )
    anchors = AnchorColumns(
        class_names=np.array(["tv"], dtype=object), positions=np.array([[0.0, 0.0, 0.5]]), sizes=np.array([size]),
        last_seen=np.array([0.0]), tracker_ids=np.array([""], dtype=object), galleries=None,
        gallery_lengths=np.zeros(1, dtype=np.intp),
    )
    return percepts, anchors


def test_the_distance_score_forgives_what_a_large_objects_extent_explains():
    # A 1 m television seen in part is centred up to half its footprint beyond 0.3 m from its
    # whole view's centre: 0.3 m off scores as the same place; a mug 0.3 m off does not.
    tv = pair_features(*_columns_at(0.3, (0.1, 1.0, 0.6)), [0], [0], FeatureConfig(), False)
    assert tv.distance[0] == pytest.approx(0.3) and tv.footprint_distance[0] == pytest.approx(0.0)
    assert tv.distance_score[0] == pytest.approx(1.0)
    farther = pair_features(*_columns_at(0.6, (0.1, 1.0, 0.6)), [0], [0], FeatureConfig(), False)
    assert farther.distance_score[0] == pytest.approx(math.exp(-(0.6 - 0.35)))
    mug = pair_features(*_columns_at(0.3, (0.1, 0.1, 0.1)), [0], [0], FeatureConfig(), False)
    assert mug.footprint_distance[0] == pytest.approx(0.3)
    assert mug.distance_score[0] == pytest.approx(math.exp(-0.3))


def test_the_separation_counts_widths_along_the_line_between_the_centres():
    # Two boxes 0.4 m apart along x: two of a 20 x 60 cm box's widths, two thirds of its width
    # turned; a 1 m television 0.2 m off is a fifth of its width.
    along_narrow_side = pair_features(*_columns_at(0.4, (0.2, 0.6, 0.25)), [0], [0], FeatureConfig(), False)
    assert along_narrow_side.separation[0] == pytest.approx(2.0)
    assert along_narrow_side.separation_score[0] == pytest.approx(math.exp(-2.0))
    along_wide_side = pair_features(*_columns_at(0.4, (0.6, 0.2, 0.25)), [0], [0], FeatureConfig(), False)
    assert along_wide_side.separation[0] == pytest.approx(0.4 / 0.6)
    # A 5 cm book is measured in the floor's width (depth noise and pose error do not shrink with it).
    book = pair_features(*_columns_at(0.3, (0.05, 0.2, 0.25)), [0], [0], FeatureConfig(), False)
    assert book.separation[0] == pytest.approx(0.3 / MINIMUM_SEPARATION_WIDTH)
    tv = pair_features(*_columns_at(0.2, (1.0, 0.1, 0.6)), [0], [0], FeatureConfig(), False)
    assert tv.separation[0] == pytest.approx(0.2)
    same_place = pair_features(*_columns_at(0.0, (0.2, 0.6, 0.25)), [0], [0], FeatureConfig(), False)
    assert same_place.separation[0] == 0.0 and same_place.separation_score[0] == 1.0


def test_the_separation_is_measured_in_the_wider_box_and_never_in_a_sliver():
    # A partial view (half the television) is measured in the whole's width, not its own.
    offsets = np.array([[0.3, 0.0, 0.0], [0.3, 0.0, 0.0], [0.0, 0.0, 0.4], [0.1, 0.1, 0.0]])
    distances = np.linalg.norm(offsets, axis=1)
    percept_sizes = np.array([[0.5, 0.1, 0.6], [0.001, 0.001, 0.1], [0.3, 0.1, 0.1], [0.3, 0.3, 0.2]])
    anchor_sizes = np.array([[1.0, 0.1, 0.6], [0.002, 0.0, 0.1], [0.1, 0.2, 0.1], [0.3, 0.3, 0.2]])
    widths = separation(offsets, distances, percept_sizes, anchor_sizes)
    assert widths[0] == pytest.approx(0.3)
    assert widths[1] == pytest.approx(0.3 / MINIMUM_SEPARATION_WIDTH)
    assert widths[2] == pytest.approx(0.4 / 0.3)  # straight above: the longest horizontal side
    assert widths[3] == pytest.approx(math.hypot(0.1, 0.1) / (0.3 * math.sqrt(2.0)))  # diagonal of a square box
