"""``sailor train``: train the matching network on pairs of the generated source.

Steps: generate the train and validation scenes (lazily, from the seed), embed every crop once
(cached under ``--cache``, so a second run embeds nothing), train with Adam (lr 0.001) on the
class-balanced training pairs, validate on every validation pair each epoch, keep the best epoch.
Writes the weights (with their metadata header), a ``.json`` provenance file beside them and a
loss-curve PNG. Uses CUDA when available (``--device``). ``--source`` trains on a public data set
instead (nuScenes or MOTFront, chosen in :mod:`merlin2_sailor.training.source_registry`); its
scenes are split by scene and the scene counts are capped at what each split holds.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import asdict
from pathlib import Path

from merlin2_sailor.training.source_registry import SOURCE_FORMS

DEFAULT_OUTPUT = "matching_network.pt"
SOURCE_HELP = f"pairs from: generated (default), {SOURCE_FORMS}"


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "train", help="train the matching network on generated pairs",
        description="Train SAILOR's matching network on percept-anchor pairs (Algorithm 3) of the "
                    "generated source: real photo crops, moving RGB-D camera, look-alikes.",
    )
    parser.add_argument("--output", default=DEFAULT_OUTPUT, metavar="PATH",
                        help=f"weights file to write (default {DEFAULT_OUTPUT}); PATH.json and PATH_loss.png beside it")
    parser.add_argument("--source", default="generated", metavar="SPEC", help=SOURCE_HELP)
    parser.add_argument("--seed", type=int, default=0, help="seed of the generated source and of training (default 0)")
    parser.add_argument("--train-scenes", type=int, default=120, metavar="N", help="training scenes (default 120)")
    parser.add_argument("--validation-scenes", type=int, default=16, metavar="N",
                        help="validation scenes (default 16)")
    parser.add_argument("--epochs", type=int, default=8, help="epochs (default 8)")
    parser.add_argument("--batch-size", type=int, default=256, help="pairs per batch (default 256)")
    parser.add_argument("--learning-rate", type=float, default=0.001,
                        help="Adam learning rate (default 0.001, the paper's)")
    parser.add_argument("--balance", type=float, default=2.0, metavar="RATIO",
                        help="different-class pairs kept per positive pair in training; a negative value keeps "
                             "every pair (default 2)")
    parser.add_argument("--time-scale", type=float, default=30.0, metavar="SECONDS",
                        help="time feature scale the network is trained for (default 30)")
    parser.add_argument("--device", choices=("auto", "cpu", "cuda"), default="auto",
                        help="auto: CUDA when available (default)")
    parser.add_argument("--cache", default=None, metavar="DIR",
                        help="embedding cache folder (default $SAILOR_CACHE or ~/.cache/merlin2_sailor/embeddings)")
    parser.add_argument("--no-cache", action="store_true", help="keep embeddings in memory only")
    parser.add_argument("--darknet", default="", metavar="DIR",
                        help="darknet photo folder (default $SAILOR_DARKNET_DATA or /usr/share/darknet/data)")
    parser.add_argument("--no-darknet", action="store_true", help="use scikit-image's photos only")
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    from merlin2_sailor.anchoring.matching_network import NetworkMetadata
    from merlin2_sailor.training.generated_dataset import TRAIN, VALIDATION, GeneratedPairSet, SplitSizes
    from merlin2_sailor.training.pair_dataset import PairDatasetConfig, dataset_hash
    from merlin2_sailor.training.plots import plot_curves
    from merlin2_sailor.training.trainer import Trainer, TrainingConfig

    started = time.perf_counter()
    source = pair_source(arguments)
    sizes = SplitSizes(train=scene_count(source, TRAIN, arguments.train_scenes),
                       validation=scene_count(source, VALIDATION, arguments.validation_scenes), test=0)
    balance = None if arguments.balance < 0 else arguments.balance
    train_pairs = PairDatasetConfig(different_class_per_positive=balance, seed=arguments.seed)
    validation_pairs = PairDatasetConfig(seed=arguments.seed)
    train_set = GeneratedPairSet(source, TRAIN, sizes.train, train_pairs)
    validation_set = GeneratedPairSet(source, VALIDATION, sizes.validation, validation_pairs)
    training = TrainingConfig(epochs=arguments.epochs, batch_size=arguments.batch_size,
                              learning_rate=arguments.learning_rate, seed=arguments.seed, device=arguments.device)
    metadata = NetworkMetadata(time_scale=arguments.time_scale)

    cache = embedding_cache(arguments, metadata.backbone)
    embedded = train_set.embed(cache) + validation_set.embed(cache)
    embedding_seconds = time.perf_counter() - started
    print(f"crops: {len(cache)} cached, {embedded} embedded now ({embedding_seconds:.1f} s)")

    output = Path(arguments.output)
    provenance = {
        "source": arguments.source,
        "source_fingerprint": source.fingerprint,
        "source_config": asdict(source.config),
        "dataset_hash": dataset_hash(source.fingerprint, sizes.as_dict(), train_pairs),
        "splits": sizes.as_dict(),
        "pairs": {"train": asdict(train_pairs), "validation": asdict(validation_pairs)},
        "backbone": metadata.backbone,
        "embedding_seconds": round(embedding_seconds, 1),
    }
    result = Trainer(metadata, cache, training).train(train_set.chunks, validation_set.chunks, output, provenance)
    curve = plot_curves(
        output.with_name(output.stem + "_loss.png"),
        {
            "train loss": [r.train_loss for r in result.history],
            "validation loss": [r.validation_loss for r in result.history],
            "validation 1 - F1": [1.0 - float(r.validation["f1"]) for r in result.history],
        },
        title=f"matching network training ({result.device})",
    )
    for record in result.history:
        v = record.validation
        print(f"epoch {record.epoch:>3}: train loss {record.train_loss:.4f}  validation loss "
              f"{record.validation_loss:.4f}  accuracy {v['accuracy']:.4f}  precision {v['precision']:.4f}  "
              f"recall {v['recall']:.4f}  F1 {v['f1']:.4f}  ({record.seconds:.1f} s)")
    print(f"best epoch {result.best_epoch} (validation F1 {result.best.validation['f1']:.4f}) -> {output}")
    print(f"provenance {output.with_suffix('.json')}, loss curve {curve}")
    print(f"total {time.perf_counter() - started:.1f} s (training {result.seconds:.1f} s on {result.device})")
    return 0


def generated_source(arguments: argparse.Namespace):  # type: ignore[no-untyped-def]
    """The generated source the arguments describe (shared with ``sailor evaluate``)."""
    from merlin2_sailor.training.generated_scenes import GeneratedSource, GeneratedSourceConfig

    return GeneratedSource(GeneratedSourceConfig(
        seed=arguments.seed, use_darknet=not arguments.no_darknet, darknet_folder=arguments.darknet))


def pair_source(arguments: argparse.Namespace):  # type: ignore[no-untyped-def]
    """The source ``--source`` names: the generated one, or a public data set's adapter."""
    if arguments.source == "generated":
        return generated_source(arguments)
    from merlin2_sailor.training.source_registry import open_source

    return open_source(arguments.source)


def scene_count(source, split: str, requested: int) -> int:  # type: ignore[no-untyped-def]
    """``requested``, or fewer when a public data set's split holds fewer scenes."""
    return min(requested, source.split_size(split)) if hasattr(source, "split_size") else requested


def embedding_cache(arguments: argparse.Namespace, backbone: str):  # type: ignore[no-untyped-def]
    """The embedding cache the arguments describe, with the backbone's crop embedder."""
    from merlin2_sailor.perception.embedding import CropEmbedder, EmbeddingConfig
    from merlin2_sailor.training.embedding_cache import EmbeddingCache
    from merlin2_sailor.training.generated_dataset import default_cache_folder

    folder = None if arguments.no_cache else (arguments.cache or default_cache_folder())
    return EmbeddingCache(CropEmbedder(EmbeddingConfig(backbone=backbone)), backbone, folder)
