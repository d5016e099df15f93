"""Percept-anchor pairs by the paper's Algorithm 3, streamed in chunks, split by scene.

Algorithm 3: per scene, every object of every sample is paired with every object seen before it
in that scene; the label is 1 when both are the same physical instance. Here "every object seen
before" means every ground-truth instance observed in an earlier sample, represented as an
anchor would hold it: its last observation before this sample (last position, last crop, the
time it was last seen). A sample with P observations after K distinct instances were seen gives
P x K pairs, at most one positive per observation; with one new object per sample this is the
n (n - 1) / 2 of the paper.

Pairs are produced scene by scene and handed out in :class:`PairChunk` s of at most
``chunk_pairs`` pairs, so memory holds one scene and one chunk whatever the data set's size.
A chunk keeps the raw states of both sides (class, position, size, stamp, crop id); features are
computed per batch by :mod:`merlin2_sailor.anchoring.features`, the one place they are defined,
with appearance read from an embedding cache by crop id.

Class-balanced sampling (for training only; evaluation uses every pair): pairs of different
classes are trivial negatives and dwarf the rest, so they are subsampled to at most
``different_class_per_positive`` per positive of the scene; positives and same-class negatives
(the hard, look-alike cases) are all kept.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Iterable, Iterator
from dataclasses import asdict, dataclass

import numpy as np

from merlin2_sailor.anchoring.features import AnchorColumns, FeatureConfig, PairFeatures, PerceptColumns, pair_features
from merlin2_sailor.anchoring.gallery import to_bfloat16_bits
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.training.generated_scenes import Observation, Scene


@dataclass(frozen=True, slots=True)
class PairDatasetConfig:
    """``chunk_pairs``: pairs per chunk; ``different_class_per_positive``: None keeps every pair,
    a number enables class-balanced sampling (see the module docstring); ``look_alike_distance``
    (m): a same-class pair nearer than this is a look-alike case (class and position agree, only
    appearance or the ground truth can tell); ``seed``: for the subsampling."""

    chunk_pairs: int = 4096
    different_class_per_positive: float | None = None
    look_alike_distance: float = 1.0
    seed: int = 0

    def __post_init__(self) -> None:
        if self.chunk_pairs < 1:
            raise ConfigurationError(f"pair dataset chunk_pairs must be at least 1, got {self.chunk_pairs}.")
        ratio = self.different_class_per_positive
        if ratio is not None and not (math.isfinite(ratio) and ratio >= 0.0):
            raise ConfigurationError(f"different_class_per_positive must be None or >= 0, got {ratio}.")
        if not (math.isfinite(self.look_alike_distance) and self.look_alike_distance > 0.0):
            raise ConfigurationError(
                f"look_alike_distance must be a positive distance, got {self.look_alike_distance}."
            )


@dataclass(frozen=True, slots=True, eq=False)
class PairChunk:
    """K pairs as columns. ``percept_*`` is the later observation, ``anchor_*`` the earlier state."""

    scene_ids: np.ndarray  # (K,) str
    percept_crop_ids: np.ndarray  # (K,) str
    percept_classes: np.ndarray  # (K,) str
    percept_positions: np.ndarray  # (K, 3)
    percept_sizes: np.ndarray  # (K, 3)
    percept_stamps: np.ndarray  # (K,)
    anchor_crop_ids: np.ndarray
    anchor_classes: np.ndarray
    anchor_positions: np.ndarray
    anchor_sizes: np.ndarray
    anchor_last_seen: np.ndarray
    labels: np.ndarray  # (K,) bool: same physical instance
    look_alike: np.ndarray  # (K,) bool: same class and nearer than look_alike_distance

    def __len__(self) -> int:
        return len(self.labels)

    def take(self, indices: np.ndarray | slice) -> PairChunk:
        return PairChunk(**{name: getattr(self, name)[indices] for name in _CHUNK_FIELDS})

    @staticmethod
    def concatenate(chunks: list[PairChunk]) -> PairChunk:
        return PairChunk(**{name: np.concatenate([getattr(c, name) for c in chunks]) for name in _CHUNK_FIELDS})

    def features(self, config: FeatureConfig, embeddings: tuple[np.ndarray, np.ndarray] | None = None) -> PairFeatures:
        """The pairs' features; ``embeddings`` = (percept rows, anchor rows), (K, D) each, for appearance.

        Anchor embeddings are stored as bfloat16, as anchors' galleries store them at run time,
        so the network trains on the numbers it will see.
        """
        count = len(self)
        empty = np.full(count, "", dtype=object)
        percepts = PerceptColumns(
            class_names=self.percept_classes,
            positions=self.percept_positions,
            sizes=self.percept_sizes,
            stamps=self.percept_stamps,
            tracker_ids=empty,
            embeddings=None if embeddings is None else np.asarray(embeddings[0], dtype=np.float32),
            has_embedding=np.full(count, embeddings is not None),
        )
        anchors = AnchorColumns(
            class_names=self.anchor_classes,
            positions=self.anchor_positions,
            sizes=self.anchor_sizes,
            last_seen=self.anchor_last_seen,
            tracker_ids=empty,
            galleries=None if embeddings is None else to_bfloat16_bits(embeddings[1])[:, np.newaxis, :],
            gallery_lengths=np.full(count, 0 if embeddings is None else 1, dtype=np.intp),
        )
        indices = np.arange(count)
        return pair_features(percepts, anchors, indices, indices, config, with_appearance=embeddings is not None)


_CHUNK_FIELDS = tuple(PairChunk.__dataclass_fields__)


def scene_pairs(scene: Scene, config: PairDatasetConfig) -> PairChunk:
    """Every pair of one scene (Algorithm 3), subsampled when class balancing is on."""
    percepts: list[Observation] = []
    anchors: list[Observation] = []
    last_seen: dict[int, Observation] = {}
    for sample in scene.samples:
        seen_before = list(last_seen.values())
        for observation in sample.observations:
            percepts += [observation] * len(seen_before)
            anchors += seen_before
        for observation in sample.observations:
            last_seen[observation.instance] = observation
    chunk = _columns(scene.scene_id, percepts, anchors, config.look_alike_distance)
    if config.different_class_per_positive is None or not len(chunk):
        return chunk
    return _balance(chunk, config, scene.scene_id)


def iter_pair_chunks(scenes: Iterable[Scene], config: PairDatasetConfig) -> Iterator[PairChunk]:
    """Stream the pairs of ``scenes`` in chunks of at most ``config.chunk_pairs`` (lazily)."""
    pending: list[PairChunk] = []
    pending_count = 0
    for scene in scenes:
        chunk = scene_pairs(scene, config)
        if not len(chunk):
            continue
        pending.append(chunk)
        pending_count += len(chunk)
        while pending_count >= config.chunk_pairs:
            merged = PairChunk.concatenate(pending)
            yield merged.take(slice(0, config.chunk_pairs))
            rest = merged.take(slice(config.chunk_pairs, None))
            pending, pending_count = ([rest], len(rest)) if len(rest) else ([], 0)
    if pending_count:
        yield PairChunk.concatenate(pending)


def dataset_hash(source_fingerprint: str, splits: dict[str, int], config: PairDatasetConfig) -> str:
    """Names a pair data set: the source, the scenes of each split and the sampling."""
    description = f"{source_fingerprint}|{sorted(splits.items())}|{sorted(asdict(config).items())}"
    return hashlib.sha256(description.encode()).hexdigest()[:16]


def _columns(scene_id: str, percepts: list[Observation], anchors: list[Observation], look_alike: float) -> PairChunk:
    count = len(percepts)

    def vectors(observations: list[Observation], name: str) -> np.ndarray:
        return np.array([getattr(o, name) for o in observations], dtype=np.float64).reshape(count, 3)

    def text(observations: list[Observation], name: str) -> np.ndarray:
        return np.array([getattr(o, name) for o in observations], dtype=object).reshape(count)

    percept_positions, anchor_positions = vectors(percepts, "position"), vectors(anchors, "position")
    percept_classes, anchor_classes = text(percepts, "class_name"), text(anchors, "class_name")
    distance = np.linalg.norm(percept_positions - anchor_positions, axis=1)
    return PairChunk(
        scene_ids=np.full(count, scene_id, dtype=object),
        percept_crop_ids=text(percepts, "crop_id"),
        percept_classes=percept_classes,
        percept_positions=percept_positions,
        percept_sizes=vectors(percepts, "size"),
        percept_stamps=np.array([o.stamp for o in percepts], dtype=np.float64),
        anchor_crop_ids=text(anchors, "crop_id"),
        anchor_classes=anchor_classes,
        anchor_positions=anchor_positions,
        anchor_sizes=vectors(anchors, "size"),
        anchor_last_seen=np.array([o.stamp for o in anchors], dtype=np.float64),
        labels=np.array([p.instance == a.instance for p, a in zip(percepts, anchors, strict=True)], dtype=bool),
        look_alike=(percept_classes == anchor_classes) & (distance < look_alike),
    )


def _balance(chunk: PairChunk, config: PairDatasetConfig, scene_id: str) -> PairChunk:
    assert config.different_class_per_positive is not None
    different = chunk.percept_classes != chunk.anchor_classes
    kept = ~different
    candidates = np.flatnonzero(different)
    quota = int(round(config.different_class_per_positive * max(int(chunk.labels.sum()), 1)))
    if quota >= len(candidates):
        kept[candidates] = True
    else:
        seed = int.from_bytes(hashlib.sha256(f"{config.seed}|{scene_id}".encode()).digest()[:8], "little")
        kept[np.random.default_rng(seed).choice(candidates, size=quota, replace=False)] = True
    return chunk.take(np.flatnonzero(kept))
