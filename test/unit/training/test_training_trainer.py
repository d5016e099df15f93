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
    metadata = NetworkMetadata(backbone="colour", feature_dimension=24, colour_bins=0, siamese_units=32,
                               branch_units=16, classifier_units=(32, 16))
    trainer = Trainer(metadata, cache, TrainingConfig(epochs=6, batch_size=64, learning_rate=3e-3, device="cpu"))
    output = tmp_path / "tiny.pt"
    result = trainer.train(train.chunks, validation.chunks, output, {"dataset_hash": "abc"})
    losses = [record.train_loss for record in result.history]
    assert losses[-1] < 0.9 * losses[0]
    # the last epoch ran at the schedule's final learning rate
    assert trainer.optimizer.param_groups[0]["lr"] == pytest.approx(trainer.config.final_learning_rate)
    network = load_network(output, "colour", 24)
    provenance = json.loads(output.with_suffix(".json").read_text())
    assert provenance["dataset_hash"] == "abc" and provenance["best_epoch"] == result.best_epoch
    assert len(provenance["history"]) == 6
    # The saved file is the best epoch's network: it reproduces that epoch's validation counts
    # (validation counts every pair, Algorithm 3's, the searched and the replaced ones, which
    # evaluation splits).
    evaluation = evaluate_pairs(NetworkMatcher(network), validation.chunks(), cache)
    true_positives = (evaluation.all_pairs.true_positives + evaluation.searched.true_positives
                      + evaluation.replaced.true_positives)
    assert evaluation.searched.total > 0 and true_positives == result.best.validation["true_positives"]


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


def test_the_learning_rate_falls_along_a_cosine_from_the_first_epoch_to_the_last() -> None:
    config = TrainingConfig(epochs=5, learning_rate=1e-3, final_learning_rate=1e-5, device="cpu")
    rates = [config.learning_rate_at(epoch) for epoch in range(1, 6)]
    assert rates[0] == pytest.approx(1e-3) and rates[-1] == pytest.approx(1e-5)
    assert rates[2] == pytest.approx((1e-3 + 1e-5) / 2)  # half way at the middle epoch
    assert all(a > b for a, b in zip(rates, rates[1:], strict=False))
    assert TrainingConfig(epochs=1, device="cpu").learning_rate_at(1) == pytest.approx(1e-3)
    with pytest.raises(ConfigurationError, match="final_learning_rate"):
        TrainingConfig(learning_rate=1e-3, final_learning_rate=1e-2)


def test_true_pairs_weigh_more_than_false_ones_and_searched_true_pairs_less_than_the_others(colour_embedder) -> None:
    import torch

    from merlin2_sailor.training.pair_dataset import scene_pairs

    scene = hand_scene([[observation(0, 0), observation(1, 0, position=(3, 0, 0))],
                        [observation(0, 1), observation(1, 1, position=(3, 0, 0))]])
    chunk = scene_pairs(scene, PairDatasetConfig(search_pairs_per_positive=1.0))
    metadata = NetworkMetadata(backbone="colour", feature_dimension=24, colour_bins=0)
    trainer = Trainer(metadata, EmbeddingCache(colour_embedder, "colour"),
                      TrainingConfig(positive_weight=8.0, searched_positive_weight=2.0, device="cpu"))
    logits = torch.zeros(len(chunk))  # every pair scored 0.5: each costs log 2 times its weight
    labels = torch.from_numpy(chunk.labels.astype(np.float32))
    weights = np.where(chunk.labels & ~chunk.searched, 8.0, np.where(chunk.labels, 2.0, 1.0))
    assert float(trainer.loss(logits, labels, chunk)) == pytest.approx(np.log(2.0) * weights.mean(), rel=1e-6)
    assert set(weights.tolist()) == {8.0, 2.0, 1.0}
