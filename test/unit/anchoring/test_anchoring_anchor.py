"""The anchor: fusion that never overwrites, and the lifecycle rules."""

from __future__ import annotations

import math

import numpy as np
import pytest

from merlin2_sailor.anchoring import AnchorState, FusionConfig, LifecycleConfig
from merlin2_sailor.anchoring.anchor import Anchor
from merlin2_sailor.anchoring.fusion import fuse_position
from merlin2_sailor.anchoring.gallery import GALLERY_DTYPE, from_bfloat16_bits
from merlin2_sailor.anchoring.lifecycle import after_expected_but_unseen, after_sighting, expire, sightings_doubled
from merlin2_sailor.errors import ConfigurationError, InvalidInputError

from .anchoring_scenes import SceneObject

CUP = SceneObject("cup", "cup", (1.0, 0.0, 0.8), (0.1, 0.1, 0.2))


def new_anchor(maker, config=None, stamp=0.0):
    return Anchor.from_percept("cup_1", maker.percept(CUP, stamp), maker.appearance("cup"), config or FusionConfig())


def test_acquired_anchor_takes_the_percept(maker):
    anchor = new_anchor(maker)
    assert anchor.state is AnchorState.TENTATIVE and anchor.times_seen == 1 and anchor.visible
    assert anchor.gallery.shape == (1, maker.dimension) and anchor.gallery.dtype == GALLERY_DTYPE
    np.testing.assert_allclose(anchor.position, CUP.position, atol=0.05)


def test_reacquire_fuses_position_instead_of_overwriting(maker):
    anchor = new_anchor(maker)
    start = anchor.position.copy()
    outlier = maker.percept(CUP, 0.1, position=np.asarray(CUP.position) + (0.5, 0.0, 0.0))
    anchor.absorb(outlier, None, FusionConfig())
    moved = np.linalg.norm(anchor.position - start)
    assert 0.1 < moved < 0.4  # pulled towards the outlier, not onto it
    assert anchor.times_seen == 2 and anchor.last_seen == 0.1


def test_position_converges_and_variance_shrinks_for_a_static_object(maker):
    anchor = new_anchor(maker)
    variances, raw_errors, fused_errors = [], [], []
    for frame in range(1, 60):
        percept = maker.percept(CUP, frame * 0.1)
        anchor.absorb(percept, None, FusionConfig())
        variances.append(anchor.position_variance)
        raw_errors.append(np.linalg.norm(percept.position - CUP.position))
        fused_errors.append(np.linalg.norm(anchor.position - CUP.position))
    assert variances[-1] < variances[0]
    # filtering averages the noise out: the anchor is nearer the truth than single percepts are
    assert np.mean(fused_errors[20:]) < 0.6 * np.mean(raw_errors[20:])


def test_long_unseen_anchor_trusts_a_new_measurement_more():
    config = FusionConfig()
    position = np.zeros(3)
    _, fresh_variance = fuse_position(position, 0.001, np.ones(3), 0.1, config)
    fresh, _ = fuse_position(position, 0.001, np.ones(3), 0.1, config)
    stale, _ = fuse_position(position, 0.001, np.ones(3), 600.0, config)
    assert fresh[0] < 0.2 < 0.9 < stale[0]
    assert fresh_variance < 0.01


def test_size_is_averaged(maker):
    anchor = new_anchor(maker)
    first = anchor.size.copy()
    anchor.absorb(maker.percept(SceneObject("cup", "cup", CUP.position, (0.3, 0.3, 0.6)), 0.1), None, FusionConfig())
    np.testing.assert_allclose(anchor.size, (first + np.array([0.3, 0.3, 0.6])) / 2.0, rtol=0.05)


def test_class_is_decided_by_votes(maker):
    anchor = new_anchor(maker)
    anchor.absorb(maker.percept(CUP, 0.1, class_name="bowl"), None, FusionConfig())
    assert anchor.class_name == "cup"  # a tie keeps the current class
    anchor.absorb(maker.percept(CUP, 0.2, class_name="bowl"), None, FusionConfig())
    assert anchor.class_name == "bowl"
    assert anchor.class_votes == pytest.approx({"cup": 0.9, "bowl": 1.8})


def test_gallery_keeps_the_last_k_embeddings(maker):
    config = FusionConfig(gallery_size=3)
    anchor = new_anchor(maker, config)
    views = [maker.appearance(f"view_{n}") for n in range(5)]
    for number, view in enumerate(views):
        anchor.absorb(maker.percept(CUP, 0.1 * (number + 1)), view, config)
        kept = min(number + 2, 3)  # the acquiring embedding, then the views, at most three
        assert len(anchor.gallery) == kept
        np.testing.assert_allclose(from_bfloat16_bits(anchor.gallery[-1]), view, rtol=2**-8)
    np.testing.assert_allclose(from_bfloat16_bits(anchor.gallery), np.stack(views[-3:]), rtol=2**-8)


def test_gallery_refuses_an_embedding_of_another_size(maker):
    anchor = new_anchor(maker)
    with pytest.raises(InvalidInputError, match="backbone changed"):
        anchor.absorb(maker.percept(CUP, 0.1), np.zeros(7, dtype=np.float32), FusionConfig())


def test_tracker_id_is_kept_when_a_percept_has_none(maker):
    anchor = Anchor.from_percept("cup_1", maker.percept(CUP, 0.0, tracker_id="4"), None, FusionConfig())
    anchor.absorb(maker.percept(CUP, 0.1, tracker_id=""), None, FusionConfig())
    assert anchor.last_tracker_id == "4"
    anchor.absorb(maker.percept(CUP, 0.2, tracker_id="9"), None, FusionConfig())
    assert anchor.last_tracker_id == "9"


def test_lifecycle_from_tentative_to_forgotten(maker):
    config = LifecycleConfig(confirm_after=3, missed_frames_to_missing=2, forget_after=10.0)
    anchor = new_anchor(maker)
    assert not after_sighting(anchor, config) and anchor.state is AnchorState.TENTATIVE
    anchor.absorb(maker.percept(CUP, 0.1), None, FusionConfig())
    assert not after_sighting(anchor, config)
    anchor.absorb(maker.percept(CUP, 0.2), None, FusionConfig())
    assert after_sighting(anchor, config) and anchor.state is AnchorState.CONFIRMED
    assert not after_expected_but_unseen(anchor, 1.0, config)
    assert after_expected_but_unseen(anchor, 2.0, config) and anchor.state is AnchorState.MISSING
    assert anchor.missing_since == 2.0
    assert not after_expected_but_unseen(anchor, 3.0, config)  # already missing: no second change
    assert not expire(anchor, 11.9, config)
    assert expire(anchor, 12.0, config) and anchor.state is AnchorState.FORGOTTEN


def test_identity_is_judged_again_each_time_the_sightings_double(maker):
    config = LifecycleConfig(confirm_after=3)
    anchor = new_anchor(maker)
    judged_at = []
    for sighting in range(2, 200):
        anchor.absorb(maker.percept(CUP, sighting * 0.1), None, FusionConfig())
        assert anchor.times_seen == sighting
        if sightings_doubled(anchor, config):
            judged_at.append(sighting)
    assert judged_at == [6, 12, 24, 48, 96, 192]


def test_reacquired_missing_anchor_returns_to_its_trust_level(maker):
    config = LifecycleConfig(confirm_after=1, missed_frames_to_missing=1)
    anchor = new_anchor(maker)
    after_sighting(anchor, config)
    after_expected_but_unseen(anchor, 1.0, config)
    anchor.absorb(maker.percept(CUP, 2.0), None, FusionConfig())
    assert after_sighting(anchor, config)  # confirmed again: it is back
    assert anchor.state is AnchorState.CONFIRMED and anchor.missing_since is None and anchor.missed_frames == 0


def test_a_missing_anchor_needs_as_many_sightings_as_a_new_one_to_come_back(maker):
    """One false detection near a lost object's old place must not say it is found."""
    config = LifecycleConfig(confirm_after=3, missed_frames_to_missing=1)
    anchor = new_anchor(maker)
    anchor.times_seen = 3
    after_sighting(anchor, config)
    after_expected_but_unseen(anchor, 1.0, config)
    assert anchor.state is AnchorState.MISSING
    assert not after_sighting(anchor, config) and not after_sighting(anchor, config)
    after_expected_but_unseen(anchor, 1.5, config)  # a frame that should have shown it did not
    assert not after_sighting(anchor, config) and not after_sighting(anchor, config)
    assert anchor.state is AnchorState.MISSING
    assert after_sighting(anchor, config) and anchor.state is AnchorState.CONFIRMED


@pytest.mark.parametrize(
    ("factory", "options"),
    [
        (FusionConfig, {"measurement_variance": 0.0}),
        (FusionConfig, {"drift_variance_rate": -1.0}),
        (FusionConfig, {"size_smoothing": 0.0}),
        (FusionConfig, {"gallery_size": 0}),
        (FusionConfig, {"initial_variance": math.nan}),
        (LifecycleConfig, {"confirm_after": 0}),
        (LifecycleConfig, {"missed_frames_to_missing": 0}),
        (LifecycleConfig, {"forget_after": -1.0}),
    ],
)
def test_invalid_configuration_names_the_field(factory, options):
    with pytest.raises(ConfigurationError, match=next(iter(options))):
        factory(**options)


def test_anchor_satisfies_the_grounding_protocols(maker):
    from merlin2_sailor.knowledge import Grounding, GroundingConfig, Waypoint

    anchor = new_anchor(maker)
    after_sighting(anchor, LifecycleConfig(confirm_after=1))
    grounding = Grounding(GroundingConfig(waypoints=(Waypoint("kitchen", 1.0, 0.0),)))
    grounded = grounding.ground([anchor])
    assert "cup_1" in grounded
