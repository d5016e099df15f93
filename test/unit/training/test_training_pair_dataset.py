"""Algorithm 3's pairs: counts, labels, anchors' states, streaming, balancing, features; and the
searched and replaced pairs added beside them (counted apart, so the counting tests turn them off)."""

from __future__ import annotations

import itertools
from collections.abc import Iterator

import numpy as np
import pytest

from merlin2_sailor.anchoring.features import FeatureConfig, encode_distance
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.training.generated_scenes import Scene
from merlin2_sailor.training.pair_dataset import REPLACED_OFFSET, PairDatasetConfig, iter_pair_chunks, scene_pairs
from merlin2_sailor.training.pair_scoring import as_run

from .conftest import hand_scene, observation

#: Only Algorithm 3's own pairs: no searched or replaced pairs beside them.
ALGORITHM_3_ONLY = {"search_pairs_per_positive": 0.0, "replaced_pairs_per_revisit": 0.0}


def test_one_new_object_per_sample_gives_n_times_n_minus_one_over_two_pairs() -> None:
    n = 7
    scene = hand_scene([[observation(i, i)] for i in range(n)])
    chunk = scene_pairs(scene, PairDatasetConfig(**ALGORITHM_3_ONLY))
    assert len(chunk) == n * (n - 1) // 2
    assert not chunk.labels.any()


def test_the_same_objects_in_every_sample_pair_with_their_last_states() -> None:
    samples, objects = 4, 3
    scene = hand_scene([[observation(i, s, position=(i, s, 0)) for i in range(objects)] for s in range(samples)])
    chunk = scene_pairs(scene, PairDatasetConfig(**ALGORITHM_3_ONLY))
    assert len(chunk) == (samples - 1) * objects * objects
    assert chunk.labels.sum() == (samples - 1) * objects  # one positive per observation after the first sample
    # The anchor is the object's state in the sample just before: last position, last crop, last time.
    assert np.all(chunk.percept_stamps - chunk.anchor_last_seen == 1.0)
    assert np.all(chunk.percept_positions[:, 1] - chunk.anchor_positions[:, 1] == 1.0)
    positives = chunk.labels
    assert all(p.split("/")[-1] == a.split("/")[-1]
               for p, a in zip(chunk.percept_crop_ids[positives], chunk.anchor_crop_ids[positives], strict=True))


def test_an_object_unseen_for_a_while_is_paired_with_its_last_sighting() -> None:
    scene = hand_scene([[observation(0, 0), observation(1, 0)], [observation(1, 1)], [observation(0, 2)]])
    chunk = scene_pairs(scene, PairDatasetConfig(**ALGORITHM_3_ONLY))
    # sample 1: 1 percept x 2 instances; sample 2: 1 percept x 2 instances.
    assert len(chunk) == 4
    last = chunk.take(slice(2, 4))
    assert list(last.labels) == [True, False]
    assert list(last.anchor_crop_ids) == ["hand/0/0", "hand/1/1"]


def test_look_alike_flags_same_class_pairs_that_are_near() -> None:
    scene = hand_scene([
        [
            observation(0, 0, "cup", (0, 0, 0)),
            observation(1, 0, "cup", (3, 0, 0)),
            observation(2, 0, "cat", (0.1, 0, 0)),
        ],
        [observation(0, 1, "cup", (0.05, 0, 0))],
    ])
    chunk = scene_pairs(scene, PairDatasetConfig(look_alike_distance=1.0))
    assert list(chunk.look_alike) == [True, False, False]


def test_class_balancing_keeps_positives_and_same_class_negatives() -> None:
    objects = [observation(i, 0, "cup" if i < 2 else f"class{i}") for i in range(12)]
    later = [observation(i, 1, "cup" if i < 2 else f"class{i}") for i in range(2)]
    scene = hand_scene([objects, later])
    everything = scene_pairs(scene, PairDatasetConfig(**ALGORITHM_3_ONLY))
    balanced = scene_pairs(scene, PairDatasetConfig(different_class_per_positive=1.0, **ALGORITHM_3_ONLY))
    same_class = everything.percept_classes == everything.anchor_classes
    assert balanced.labels.sum() == everything.labels.sum() == 2
    assert np.sum(balanced.percept_classes == balanced.anchor_classes) == same_class.sum()
    assert np.sum(balanced.percept_classes != balanced.anchor_classes) == 2  # 1 per positive
    with pytest.raises(ConfigurationError, match="different_class_per_positive"):
        PairDatasetConfig(different_class_per_positive=-1.0, **ALGORITHM_3_ONLY)


def test_chunks_are_bounded_and_lose_nothing() -> None:
    scenes = [hand_scene([[observation(i, i)] for i in range(9)], f"hand/{k}") for k in range(5)]
    chunks = list(iter_pair_chunks(scenes, PairDatasetConfig(chunk_pairs=10, **ALGORITHM_3_ONLY)))
    assert all(len(chunk) <= 10 for chunk in chunks)
    assert sum(len(chunk) for chunk in chunks) == 5 * 36


def test_streaming_never_materialises_the_scenes() -> None:
    generated = 0

    def endless() -> Iterator[Scene]:
        nonlocal generated
        for k in itertools.count():
            generated += 1
            yield hand_scene([[observation(i, i)] for i in range(9)], f"hand/{k}")

    config = PairDatasetConfig(chunk_pairs=50, **ALGORITHM_3_ONLY)
    first = list(itertools.islice(iter_pair_chunks(endless(), config), 3))
    assert [len(chunk) for chunk in first] == [50, 50, 50]
    assert generated <= 5  # 150 pairs need 5 scenes of 36 pairs, not an endless list


def test_features_are_the_anchoring_layers_features() -> None:
    scene = hand_scene([[observation(0, 0, position=(0, 0, 0))], [observation(0, 1, position=(0.5, 0, 0), stamp=31.0)]])
    chunk = scene_pairs(scene, PairDatasetConfig(**ALGORITHM_3_ONLY))
    features = chunk.features(FeatureConfig(time_scale=30.0))
    assert features.same_class.tolist() == [True]
    np.testing.assert_allclose(features.distance_score, encode_distance(np.array([0.5])))
    np.testing.assert_allclose(features.time_score, 2.0 / (1.0 + np.exp(31.0 / 30.0)))
    embeddings = (np.ones((1, 4), np.float32), np.full((1, 4), 0.25, np.float32))
    with_appearance = chunk.features(FeatureConfig(), embeddings)
    np.testing.assert_allclose(with_appearance.appearance_difference, [[0.75] * 4])


def _fused_scene() -> Scene:
    """Object 0 seen three times, as a source that knows the anchoring layer's state describes it:
    the anchor sits where whole views put it and keeps a gallery of its last views; object 1 once."""
    first = observation(0, 0, position=(0.0, 0, 0), anchor_position=np.zeros(3), anchor_size=np.full(3, 0.2),
                        gallery=("hand/0/0",))
    second = observation(0, 1, position=(0.4, 0, 0), partial=True, anchor_position=np.zeros(3),
                         anchor_size=np.full(3, 0.2), gallery=("hand/0/0", "hand/1/0"))
    other = observation(1, 1, position=(3.0, 0, 0))
    third = observation(0, 2, position=(0.05, 0, 0))
    return hand_scene([[first], [second, other], [third]])


def test_a_known_anchor_state_is_the_anchor_side_of_its_pairs() -> None:
    chunk = scene_pairs(_fused_scene(), PairDatasetConfig(**ALGORITHM_3_ONLY))
    # sample 1 pairs with object 0's first state; sample 2 with object 0's second and object 1's only one
    assert chunk.labels.tolist() == [True, False, True, False]
    third_vs_zero = 2
    np.testing.assert_allclose(chunk.anchor_positions[third_vs_zero], [0.0, 0.0, 0.0])  # not the partial view's 0.4
    assert chunk.anchor_gallery_ids[third_vs_zero].tolist() == ["hand/0/0", "hand/1/0"]
    # without a known state, the anchor is the last observation itself, with a gallery of one
    np.testing.assert_allclose(chunk.anchor_positions[3], [3.0, 0.0, 0.0])
    assert chunk.anchor_gallery_ids[3].tolist() == ["hand/1/1", ""]
    assert chunk.gallery_lengths.tolist() == [1, 1, 2, 1]
    # a pair is partial when either side's view is: the partial view as percept, then as the anchor's last
    assert chunk.partial.tolist() == [True, False, True, False]
    assert chunk.percept_partial.tolist() == [True, False, False, False]


def test_as_run_a_partial_percepts_look_is_not_compared() -> None:
    """The anchoring layer never compares a partial view's crop (its matcher falls back to the
    rules for it); an evaluation "as run" hands the matcher the same features."""
    chunk = scene_pairs(_fused_scene(), PairDatasetConfig(**ALGORITHM_3_ONLY))
    rng = np.random.default_rng(0)
    embeddings = (rng.random((len(chunk), 8), dtype=np.float32), rng.random((len(chunk), 8), dtype=np.float32))
    features = chunk.features(FeatureConfig(), embeddings)
    assert features.appearance_known.all()
    assert as_run(features, chunk).appearance_known.tolist() == [False, True, True, True]


def test_the_gallery_entry_nearest_the_percept_is_compared() -> None:
    chunk = scene_pairs(_fused_scene(), PairDatasetConfig(**ALGORITHM_3_ONLY))
    rows = {"hand/0/0": 0.0, "hand/1/0": 1.0, "hand/1/1": 5.0, "hand/2/0": 0.9}

    def lookup(ids):  # noqa: ANN001, ANN202
        return np.array([[rows[i]] * 4 for i in ids], dtype=np.float32)

    percepts, galleries = chunk.embeddings(lookup)
    assert galleries.shape == (4, 2, 4) and not galleries[3, 1].any()
    features = chunk.features(FeatureConfig(), (percepts, galleries))
    # the third view (0.9) is compared with the second gallery entry (1.0), the nearer one
    np.testing.assert_allclose(features.appearance_difference[2], 0.1, rtol=1e-2)


def test_chunks_of_different_gallery_widths_concatenate() -> None:
    wide = scene_pairs(_fused_scene(), PairDatasetConfig(**ALGORITHM_3_ONLY))
    narrow = scene_pairs(hand_scene([[observation(0, 0)], [observation(0, 1)]], "hand/1"),
                         PairDatasetConfig(**ALGORITHM_3_ONLY))
    both = type(wide).concatenate([narrow, wide])
    assert both.anchor_gallery_ids.shape == (len(narrow) + len(wide), 2)
    assert both.anchor_gallery_ids[0].tolist() == ["hand/0/0", ""]


def test_searched_pairs_copy_true_and_false_pairs_with_a_radius_that_covers_them() -> None:
    scene = hand_scene([[observation(0, 0, position=(0, 0, 0)), observation(1, 0, position=(3, 0, 0))],
                        [observation(0, 1, position=(0.02, 0, 0)), observation(1, 1, position=(3.01, 0, 0))]])
    plain = scene_pairs(scene, PairDatasetConfig(**ALGORITHM_3_ONLY))
    assert not plain.searched.any() and len(plain) == 4
    chunk = scene_pairs(scene, PairDatasetConfig(search_pairs_per_positive=1.0, replaced_pairs_per_revisit=0.0))
    searched = chunk.take(chunk.searched)
    assert len(chunk) == len(plain) + len(searched) and len(searched) == 2
    assert searched.labels.tolist().count(True) == 1  # half true, half same-class false
    assert not searched.look_alike.any()  # not Algorithm 3's: counted apart
    features = searched.features(FeatureConfig())
    distance = np.linalg.norm(searched.percept_positions - searched.anchor_positions, axis=1)
    assert np.all(searched.anchor_search_radii >= distance)
    np.testing.assert_allclose(features.distance, 0.0)  # anywhere in the disc is "here"
    assert features.searched.all() and not plain.features(FeatureConfig()).searched.any()


def test_replaced_pairs_put_another_object_of_the_class_where_the_anchor_stood_but_never_a_twin() -> None:
    scene = hand_scene([[observation(0, 0, position=(0, 0, 0)), observation(1, 0, position=(3, 0, 0)),
                         observation(2, 0, position=(6, 0, 0), twin=True),
                         observation(3, 0, position=(9, 0, 0), twin=True)],
                        [observation(0, 1, position=(0.02, 0, 0), stamp=20.0),
                         observation(1, 1, position=(3.01, 0, 0), stamp=20.0),
                         observation(2, 1, position=(6, 0, 0), stamp=20.0, twin=True),
                         observation(3, 1, position=(9, 0, 0), stamp=20.0, twin=True)]])
    plain = scene_pairs(scene, PairDatasetConfig(**ALGORITHM_3_ONLY))
    chunk = scene_pairs(scene, PairDatasetConfig(search_pairs_per_positive=0.0, replaced_pairs_per_revisit=10.0))
    replaced = chunk.take(chunk.replaced)
    false_same_class = int((~plain.labels & (plain.percept_classes == plain.anchor_classes) & ~plain.twins).sum())
    assert len(replaced) == false_same_class == 12 - 2  # every false pair but the two between the twins
    assert not replaced.labels.any() and not replaced.look_alike.any() and not replaced.searched.any()
    assert not replaced.twins.any()
    offsets = np.linalg.norm(replaced.percept_positions - replaced.anchor_positions, axis=1)
    assert np.all(offsets <= REPLACED_OFFSET + 1e-9)  # where the anchor stood, not where the percept was
    features = replaced.features(FeatureConfig())
    assert not features.searched.any() and np.all(features.distance <= REPLACED_OFFSET + 1e-9)
    # the percept keeps its own crop, size and time: only its place (and its anchor's last sighting) change
    originals = {(p, a) for p, a in zip(plain.percept_crop_ids, plain.anchor_crop_ids, strict=True)}
    assert all((p, a) in originals for p, a in zip(replaced.percept_crop_ids, replaced.anchor_crop_ids, strict=True))


def test_a_replaced_pairs_anchor_was_last_seen_a_while_before_never_a_frame_ago() -> None:
    # Frames a third of a second apart, then the robot comes back after a minute: the false pairs
    # copied are mostly a frame apart in time, and the last frame's true pairs are revisits.
    stamps = [0.0, 1 / 3, 2 / 3, 1.0, 61.0]
    samples = [[observation(k, s, position=(3.0 * k, 0, 0), stamp=stamp) for k in range(4)]
               for s, stamp in enumerate(stamps)]
    plain = scene_pairs(hand_scene(samples), PairDatasetConfig(**ALGORITHM_3_ONLY))
    assert np.median(plain.percept_stamps - plain.anchor_last_seen) < 0.7
    config = PairDatasetConfig(search_pairs_per_positive=0.0, replaced_pairs_per_revisit=5.0,
                               replaced_absence=(20.0, 600.0))
    replaced = scene_pairs(hand_scene(samples), config).take(slice(len(plain), None))
    assert replaced.replaced.all() and len(replaced) == 5 * 4  # the 4 revisits of the last frame
    absence = replaced.percept_stamps - replaced.anchor_last_seen
    assert absence.min() >= 20.0 and absence.max() <= 600.0
    assert absence.max() > 100.0  # spread over the range (log-uniform), not piled at its start
    features = replaced.features(FeatureConfig())
    np.testing.assert_allclose(features.time_difference, absence)


def test_without_revisits_there_are_no_replaced_pairs() -> None:
    samples = [[observation(k, s, position=(3.0 * k, 0, 0), stamp=s / 3) for k in range(3)] for s in range(4)]
    chunk = scene_pairs(hand_scene(samples), PairDatasetConfig(search_pairs_per_positive=0.0,
                                                                replaced_pairs_per_revisit=5.0))
    assert not chunk.replaced.any()


@pytest.mark.parametrize("absence", [(0.0, 10.0), (30.0, 20.0), (5.0, float("inf"))])
def test_a_replaced_absence_that_is_not_a_range_of_seconds_is_refused(absence: tuple[float, float]) -> None:
    with pytest.raises(ConfigurationError, match="replaced_absence"):
        PairDatasetConfig(replaced_absence=absence)
