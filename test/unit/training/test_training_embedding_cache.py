"""The embedding cache: every crop through the backbone once, persisted, reloaded."""

from __future__ import annotations

import numpy as np
import pytest

from merlin2_sailor.errors import ConfigurationError, InvalidInputError
from merlin2_sailor.training.embedding_cache import EmbeddingCache
from merlin2_sailor.training.pair_dataset import PairDatasetConfig, iter_pair_chunks

from .conftest import hand_scene, observation


def _render(observation) -> np.ndarray:  # noqa: ANN001
    value = (37 * observation.instance + 11 * observation.sample) % 256
    return np.full((8, 8, 3), value, dtype=np.uint8)


def test_each_crop_is_embedded_once_however_many_pairs_use_it(colour_embedder, tmp_path) -> None:
    scene = hand_scene([[observation(i, s) for i in range(4)] for s in range(5)])
    cache = EmbeddingCache(colour_embedder, "colour", tmp_path, batch_crops=3)
    assert cache.ensure(scene.observations, _render) == 20
    assert cache.ensure(scene.observations, _render) == 0
    assert colour_embedder.crops == 20
    for chunk in iter_pair_chunks([scene], PairDatasetConfig()):
        assert cache.lookup(chunk.percept_crop_ids).shape == (len(chunk), 24)
        cache.lookup(chunk.anchor_crop_ids)
    assert colour_embedder.crops == 20  # 48 pairs read 96 embeddings, none recomputed


def test_the_cache_persists_and_a_new_instance_embeds_nothing(colour_embedder, tmp_path) -> None:
    scene = hand_scene([[observation(i, s) for i in range(3)] for s in range(2)])
    first = EmbeddingCache(colour_embedder, "colour", tmp_path)
    first.ensure(scene.observations, _render)
    second = EmbeddingCache(colour_embedder, "colour", tmp_path)
    assert second.ensure(scene.observations, _render) == 0
    assert colour_embedder.crops == 6
    ids = [o.crop_id for o in scene.observations]
    np.testing.assert_array_equal(first.lookup(ids), second.lookup(ids))
    assert len(list((tmp_path / "colour").glob("shard-*.npz"))) == 1


def test_duplicated_observations_in_one_call_are_embedded_once(colour_embedder) -> None:
    observations = [observation(0, 0)] * 5
    cache = EmbeddingCache(colour_embedder, "colour")
    assert cache.ensure(observations, _render) == 1
    assert colour_embedder.crops == 1


def test_unknown_crops_and_bad_namespaces_give_clear_errors(colour_embedder) -> None:
    cache = EmbeddingCache(colour_embedder, "colour")
    with pytest.raises(InvalidInputError, match="never embedded"):
        cache.lookup(["nobody"])
    with pytest.raises(ConfigurationError, match="namespace"):
        EmbeddingCache(colour_embedder, "a/b")



def test_crops_are_asked_for_while_their_scene_is_at_hand(colour_embedder, tmp_path) -> None:
    # A source that keeps only its last scenes' crops (the house source renders a whole tour to
    # make them) must be asked for each crop before more scenes are made: the cache streams.
    made: list[int] = []

    def scenes():  # noqa: ANN202
        for index in range(4):
            made.append(index)
            yield hand_scene([[observation(i, 10 * index + s) for i in range(3)] for s in range(2)], f"hand/{index}")

    def render(item) -> np.ndarray:  # noqa: ANN001
        scene = item.sample // 10
        assert scene >= made[-1] - 1, f"crop of scene {scene} asked for after scenes {made} were made"
        return _render(item)

    cache = EmbeddingCache(colour_embedder, "colour", tmp_path, batch_crops=4)
    assert cache.ensure((o for scene in scenes() for o in scene.observations), render) == 24
    assert len(list((tmp_path / "colour").glob("shard-*.npz"))) == 1
