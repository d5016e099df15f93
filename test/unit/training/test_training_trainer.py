"""Training on a tiny generated set: the loss falls, the best epoch is saved with its header."""

from __future__ import annotations

import json

import numpy as np
import pytest

from merlin2_sailor.anchoring.matching_network import NetworkMatcher, NetworkMetadata, load_network
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.training.embedding_cache import EmbeddingCache
from merlin2_sailor.training.generated_dataset import GeneratedPairSet
from merlin2_sailor.training.generated_scenes import GeneratedSource, GeneratedSourceConfig, SceneConfig
from merlin2_sailor.training.pair_dataset import PairChunk, PairDatasetConfig
from merlin2_sailor.training.pair_scoring import evaluate_pairs
from merlin2_sailor.training.trainer import Trainer, TrainingConfig, shuffled_batches

from .conftest import hand_scene, observation


def test_a_tiny_training_lowers_the_loss_and_keeps_the_best_epoch(colour_embedder, tmp_path) -> None:
    source = GeneratedSource(GeneratedSourceConfig(seed=1, use_darknet=False, scene=SceneConfig(samples=6)))
    train = GeneratedPairSet(source, "train", 6, PairDatasetConfig(different_class_per_positive=2.0))
    validation = GeneratedPairSet(source, "validation", 2, PairDatasetConfig())
    cache = EmbeddingCache(colour_embedder, "colour")
    train.embed(cache)
    validation.embed(cache)
    metadata = NetworkMetadata(backbone="colour", feature_dimension=24, siamese_units=32, branch_units=16,
                               classifier_units=(32, 16))
    trainer = Trainer(metadata, cache, TrainingConfig(epochs=6, batch_size=64, device="cpu"))
    output = tmp_path / "tiny.pt"
    result = trainer.train(train.chunks, validation.chunks, output, {"dataset_hash": "abc"})
    losses = [record.train_loss for record in result.history]
    assert losses[-1] < 0.9 * losses[0]
    network = load_network(output, "colour", 24)
    provenance = json.loads(output.with_suffix(".json").read_text())
    assert provenance["dataset_hash"] == "abc" and provenance["best_epoch"] == result.best_epoch
    assert len(provenance["history"]) == 6
    # The saved file is the best epoch's network: it reproduces that epoch's validation counts.
    evaluation = evaluate_pairs(NetworkMatcher(network), validation.chunks(), cache)
    assert evaluation.all_pairs.as_dict()["true_positives"] == result.best.validation["true_positives"]


def test_shuffled_batches_cover_every_pair_once() -> None:
    scenes = [hand_scene([[observation(i, i)] for i in range(8)], f"hand/{k}") for k in range(4)]
    from merlin2_sailor.training.pair_dataset import iter_pair_chunks

    chunks = list(iter_pair_chunks(scenes, PairDatasetConfig(chunk_pairs=7)))
    batches = list(shuffled_batches(iter(chunks), 5, 20, np.random.default_rng(0)))
    everything = PairChunk.concatenate(batches)
    keys = sorted(zip(everything.scene_ids, everything.percept_crop_ids, everything.anchor_crop_ids, strict=True))
    expected = sorted(zip(*(np.concatenate([getattr(c, n) for c in chunks])
                            for n in ("scene_ids", "percept_crop_ids", "anchor_crop_ids")), strict=True))
    assert keys == expected
    assert all(len(batch) <= 5 for batch in batches)


def test_training_configuration_is_validated() -> None:
    with pytest.raises(ConfigurationError, match="learning_rate"):
        TrainingConfig(learning_rate=0.0)
    with pytest.raises(ConfigurationError, match="device"):
        TrainingConfig(device="tpu")
