"""Algorithm 3's pairs: counts, labels, anchors' states, streaming, balancing, features."""

from __future__ import annotations

import itertools
from collections.abc import Iterator

import numpy as np
import pytest

from merlin2_sailor.anchoring.features import FeatureConfig, encode_distance
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.training.generated_scenes import Scene
from merlin2_sailor.training.pair_dataset import PairDatasetConfig, iter_pair_chunks, scene_pairs

from .conftest import hand_scene, observation


def test_one_new_object_per_sample_gives_n_times_n_minus_one_over_two_pairs() -> None:
    n = 7
    scene = hand_scene([[observation(i, i)] for i in range(n)])
    chunk = scene_pairs(scene, PairDatasetConfig())
    assert len(chunk) == n * (n - 1) // 2
    assert not chunk.labels.any()


def test_the_same_objects_in_every_sample_pair_with_their_last_states() -> None:
    samples, objects = 4, 3
    scene = hand_scene([[observation(i, s, position=(i, s, 0)) for i in range(objects)] for s in range(samples)])
    chunk = scene_pairs(scene, PairDatasetConfig())
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
    chunk = scene_pairs(scene, PairDatasetConfig())
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
    everything = scene_pairs(scene, PairDatasetConfig())
    balanced = scene_pairs(scene, PairDatasetConfig(different_class_per_positive=1.0))
    same_class = everything.percept_classes == everything.anchor_classes
    assert balanced.labels.sum() == everything.labels.sum() == 2
    assert np.sum(balanced.percept_classes == balanced.anchor_classes) == same_class.sum()
    assert np.sum(balanced.percept_classes != balanced.anchor_classes) == 2  # 1 per positive
    with pytest.raises(ConfigurationError, match="different_class_per_positive"):
        PairDatasetConfig(different_class_per_positive=-1.0)


def test_chunks_are_bounded_and_lose_nothing() -> None:
    scenes = [hand_scene([[observation(i, i)] for i in range(9)], f"hand/{k}") for k in range(5)]
    chunks = list(iter_pair_chunks(scenes, PairDatasetConfig(chunk_pairs=10)))
    assert all(len(chunk) <= 10 for chunk in chunks)
    assert sum(len(chunk) for chunk in chunks) == 5 * 36


def test_streaming_never_materialises_the_scenes() -> None:
    generated = 0

    def endless() -> Iterator[Scene]:
        nonlocal generated
        for k in itertools.count():
            generated += 1
            yield hand_scene([[observation(i, i)] for i in range(9)], f"hand/{k}")

    first = list(itertools.islice(iter_pair_chunks(endless(), PairDatasetConfig(chunk_pairs=50)), 3))
    assert [len(chunk) for chunk in first] == [50, 50, 50]
    assert generated <= 5  # 150 pairs need 5 scenes of 36 pairs, not an endless list


def test_features_are_the_anchoring_layers_features() -> None:
    scene = hand_scene([[observation(0, 0, position=(0, 0, 0))], [observation(0, 1, position=(0.5, 0, 0), stamp=31.0)]])
    chunk = scene_pairs(scene, PairDatasetConfig())
    features = chunk.features(FeatureConfig(time_scale=30.0))
    assert features.same_class.tolist() == [True]
    np.testing.assert_allclose(features.distance_score, encode_distance(np.array([0.5])))
    np.testing.assert_allclose(features.time_score, 2.0 / (1.0 + np.exp(31.0 / 30.0)))
    embeddings = (np.ones((1, 4), np.float32), np.full((1, 4), 0.25, np.float32))
    with_appearance = chunk.features(FeatureConfig(), embeddings)
    np.testing.assert_allclose(with_appearance.appearance_difference, [[0.75] * 4])
