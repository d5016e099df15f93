"""Percept-anchor pairs by the paper's Algorithm 3, streamed in chunks, split by scene.

Algorithm 3: per scene, every object of every sample is paired with every object seen before it
in that scene; the label is 1 when both are the same physical instance. Here "every object seen
before" means every ground-truth instance observed in an earlier sample, represented as an
anchor would hold it: its last observation before this sample (last position, last crop, the
time it was last seen). A sample with P observations after K distinct instances were seen gives
P x K pairs, at most one positive per observation; with one new object per sample this is the
n (n - 1) / 2 of the paper.

A source that knows how the anchoring layer would hold each instance (fused position and size, a
gallery of recent views: see :class:`~.generated_scenes.Observation`) gives the anchor side as
that state; the network then trains on the pairs it will score on the robot. Otherwise the
anchor side is the instance's last observation.

Pairs are produced scene by scene and handed out in :class:`PairChunk` s of at most
``chunk_pairs`` pairs, so memory holds one scene and one chunk whatever the data set's size.
A chunk keeps the raw states of both sides (class, position, size, stamp, crop id); features are
computed per batch by :mod:`merlin2_sailor.anchoring.features`, the one place they are defined,
with appearance read from an embedding cache by crop id.

Searched pairs: when an action searches for an anchor (an expectation with a radius), the
anchoring layer measures a candidate's distance from the searched disc, so every candidate in it
is "here" and only appearance, size and time can tell the sought object from another of its
class: a red mug from the green one in the room searched. Algorithm 3 has no such pair (two
objects are never at one place), so a network trained on it alone learns "same class, same
place: same object" and scores the green mug 1.0. With ``search_pairs_per_positive``, each scene
adds that many searched pairs per positive pair, half true pairs and half same-class false ones,
copies of its own pairs with the anchor's search radius set to cover their distance, exactly as
the matching table would see them; ``searched`` marks them (they are not Algorithm 3's, so the
pair metrics count them apart).

Replaced pairs: the same lesson without a search. An object swapped with, or replaced by,
another of its class that looks different stands exactly where the anchor was; a network that
has only seen searched pairs uses appearance only when searching, and takes a green mug in the
red mug's place for the red mug (score 1.0, measured). So each scene adds copies of its
same-class false pairs (never of two twins, which nothing could tell apart) with the percept
moved to within a few centimetres of the anchor's place; ``replaced`` marks them, and the pair
metrics count them apart too.

A replacement happens while the camera looks elsewhere, so a replaced pair's anchor was last
seen a while before (``replaced_absence``, log-uniform seconds), never the fraction of a second
between two frames that the false pair it copies may have had; and what it competes with is a
revisit, the same object seen again after such an absence, so there are
``replaced_pairs_per_revisit`` of them per true pair with that long a gap. Both choices were
measured by replaying the anchoring layer over the 10 held-out houses (167 objects). Copied with
their own short gaps, at 0.5 per positive pair, the replaced pairs taught the network that an
object in the very place of an anchor seen a frame ago may be another one: 223 anchors, 141
identity switches; 52 of the 56 extra anchors were views rejected at the anchor's own place
(0.0-0.2 m), 15 of them a third of a second after it was last seen. Given long gaps but still
counted per positive pair (nearly all of which are a frame apart), they outnumbered the revisits
several times, and the network doubted every revisit instead: 237 anchors. Counted per revisit:
0.5 gives 181 anchors and 33 switches, 1 gives 199 and 63, 2 gives 218 and 91. (Searched pairs
given such gaps too changed nothing measurable: 181 anchors, 39 switches.)

Class-balanced sampling (for training only; evaluation uses every pair): pairs of different
classes are trivial negatives and dwarf the rest, so they are subsampled to at most
``different_class_per_positive`` per positive of the scene; positives and same-class negatives
(the hard, look-alike cases) are all kept.
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
from collections.abc import Callable, Iterable, Iterator
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
    appearance or the ground truth can tell); ``search_pairs_per_positive``: searched pairs added
    per positive pair, ``replaced_pairs_per_revisit``: replaced pairs added per revisit (a positive
    pair whose anchor was last seen at least the shortest ``replaced_absence`` before), see the
    module docstring (0 adds none); ``replaced_absence`` (s): the range, log-uniform, of how long
    before a replaced pair's percept its anchor was last seen; ``seed``: for the subsampling."""

    chunk_pairs: int = 4096
    different_class_per_positive: float | None = None
    look_alike_distance: float = 1.0
    search_pairs_per_positive: float = 1.0
    replaced_pairs_per_revisit: float = 0.5
    replaced_absence: tuple[float, float] = (20.0, 600.0)
    seed: int = 0

    def __post_init__(self) -> None:
        if self.chunk_pairs < 1:
            raise ConfigurationError(f"pair dataset chunk_pairs must be at least 1, got {self.chunk_pairs}.")
        ratio = self.different_class_per_positive
        if ratio is not None and not (math.isfinite(ratio) and ratio >= 0.0):
            raise ConfigurationError(f"different_class_per_positive must be None or >= 0, got {ratio}.")
        for name in ("search_pairs_per_positive", "replaced_pairs_per_revisit"):
            if not (math.isfinite(getattr(self, name)) and getattr(self, name) >= 0.0):
                raise ConfigurationError(f"{name} must be >= 0, got {getattr(self, name)}.")
        shortest, longest = self.replaced_absence
        if not (math.isfinite(shortest) and math.isfinite(longest) and 0.0 < shortest <= longest):
            raise ConfigurationError(
                f"replaced_absence must be (shortest, longest) seconds with 0 < shortest <= longest, "
                f"got {self.replaced_absence}."
            )
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
    anchor_gallery_ids: np.ndarray  # (K, G) str: the anchor's gallery, "" past its length
    labels: np.ndarray  # (K,) bool: same physical instance
    look_alike: np.ndarray  # (K,) bool: same class and nearer than look_alike_distance
    partial: np.ndarray  # (K,) bool: the percept or the anchor's last view is a partial view
    percept_partial: np.ndarray  # (K,) bool: the percept is, so the anchoring layer scores it without its look
    anchor_search_radii: np.ndarray  # (K,) m: the radius of a search for the anchor (0: none)
    searched: np.ndarray  # (K,) bool: a searched pair (see the module docstring), not Algorithm 3's
    replaced: np.ndarray  # (K,) bool: a replaced pair (see the module docstring), not Algorithm 3's
    twins: np.ndarray  # (K,) bool: both sides are of instances that copy another's photo

    def __len__(self) -> int:
        return len(self.labels)

    def take(self, indices: np.ndarray | slice) -> PairChunk:
        return PairChunk(**{name: getattr(self, name)[indices] for name in _CHUNK_FIELDS})

    @staticmethod
    def concatenate(chunks: list[PairChunk]) -> PairChunk:
        width = max(chunk.anchor_gallery_ids.shape[1] for chunk in chunks)
        columns = {name: np.concatenate([getattr(c, name) for c in chunks]) for name in _CHUNK_FIELDS
                   if name != "anchor_gallery_ids"}
        columns["anchor_gallery_ids"] = np.concatenate([_padded(c.anchor_gallery_ids, width) for c in chunks])
        return PairChunk(**columns)

    @property
    def gallery_lengths(self) -> np.ndarray:
        return (self.anchor_gallery_ids != "").sum(axis=1)

    def embeddings(self, lookup: Callable[[np.ndarray], np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """(percept rows (K, D), anchor galleries (K, G, D), zero past each gallery's length) from a
        crop-id lookup such as :meth:`~.embedding_cache.EmbeddingCache.lookup`."""
        percepts = np.asarray(lookup(self.percept_crop_ids), dtype=np.float32)
        ids = self.anchor_gallery_ids
        valid = ids != ""
        galleries = np.zeros((*ids.shape, percepts.shape[1]), dtype=np.float32)
        if valid.any():
            galleries[valid] = lookup(ids[valid])
        return percepts, galleries

    def features(self, config: FeatureConfig, embeddings: tuple[np.ndarray, np.ndarray] | None = None) -> PairFeatures:
        """The pairs' features; ``embeddings`` = (percept rows (K, D), anchor rows (K, D) or galleries
        (K, G, D) as :meth:`embeddings` gives them) for appearance.

        Anchor embeddings are stored as bfloat16, as anchors' galleries store them at run time,
        and the gallery entry nearest the percept is compared, as at run time, so the network
        trains on the numbers it will see.
        """
        count = len(self)
        empty = np.full(count, "", dtype=object)
        galleries, lengths = None, np.zeros(count, dtype=np.intp)
        if embeddings is not None:
            anchor_rows = np.asarray(embeddings[1], dtype=np.float32)
            if anchor_rows.ndim == 2:
                anchor_rows, lengths = anchor_rows[:, np.newaxis, :], np.ones(count, dtype=np.intp)
            else:
                lengths = np.maximum(self.gallery_lengths, 1)
            galleries = to_bfloat16_bits(anchor_rows)
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
            galleries=galleries,
            gallery_lengths=lengths,
            search_radii=self.anchor_search_radii if np.any(self.anchor_search_radii > 0.0) else None,
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
    if not len(chunk):
        return chunk
    extra = [pairs for pairs in (_searched(chunk, config, scene.scene_id), _replaced(chunk, config, scene.scene_id))
             if len(pairs)]
    if config.different_class_per_positive is not None:
        chunk = _balance(chunk, config, scene.scene_id)
    return PairChunk.concatenate([chunk, *extra]) if extra else chunk


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

    def vectors(observations: list[Observation], name: str, fallback: str | None = None) -> np.ndarray:
        values = [getattr(o, name) if fallback is None or getattr(o, name) is not None else getattr(o, fallback)
                  for o in observations]
        return np.array(values, dtype=np.float64).reshape(count, 3)

    def text(observations: list[Observation], name: str) -> np.ndarray:
        return np.array([getattr(o, name) for o in observations], dtype=object).reshape(count)

    galleries = [o.gallery or (o.crop_id,) for o in anchors]
    width = max((len(g) for g in galleries), default=1)
    gallery_ids = np.full((count, width), "", dtype=object)
    for row, gallery in enumerate(galleries):
        gallery_ids[row, : len(gallery)] = gallery
    percept_positions = vectors(percepts, "position")
    anchor_positions = vectors(anchors, "anchor_position", "position")
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
        anchor_sizes=vectors(anchors, "anchor_size", "size"),
        anchor_last_seen=np.array([o.stamp for o in anchors], dtype=np.float64),
        anchor_gallery_ids=gallery_ids,
        labels=np.array([p.instance == a.instance for p, a in zip(percepts, anchors, strict=True)], dtype=bool),
        look_alike=(percept_classes == anchor_classes) & (distance < look_alike),
        partial=np.array([p.partial or a.partial for p, a in zip(percepts, anchors, strict=True)], dtype=bool),
        percept_partial=np.array([p.partial for p in percepts], dtype=bool).reshape(count),
        anchor_search_radii=np.zeros(count),
        searched=np.zeros(count, dtype=bool),
        replaced=np.zeros(count, dtype=bool),
        twins=np.array([p.twin and a.twin for p, a in zip(percepts, anchors, strict=True)], dtype=bool),
    )


def _searched(chunk: PairChunk, config: PairDatasetConfig, scene_id: str) -> PairChunk:
    """Searched copies of some of the scene's pairs: true ones and same-class false ones, in equal
    numbers, with a search radius that covers each pair's distance (see the module docstring)."""
    count = int(round(config.search_pairs_per_positive * int(chunk.labels.sum()) / 2.0))
    if count == 0:
        return chunk.take(slice(0, 0))
    seed = int.from_bytes(hashlib.sha256(f"{config.seed}|search|{scene_id}".encode()).digest()[:8], "little")
    rng = np.random.default_rng(seed)
    true_pairs = np.flatnonzero(chunk.labels)
    false_pairs = np.flatnonzero(~chunk.labels & (chunk.percept_classes == chunk.anchor_classes))
    chosen = [rng.choice(rows, size=min(count, len(rows)), replace=False) for rows in (true_pairs, false_pairs)]
    searched = chunk.take(np.sort(np.concatenate(chosen)))
    distance = np.linalg.norm(searched.percept_positions - searched.anchor_positions, axis=1)
    radii = distance + rng.uniform(0.0, 1.0, size=len(distance))  # the candidate anywhere in the disc
    return dataclasses.replace(searched, anchor_search_radii=radii, searched=np.ones(len(searched), dtype=bool),
                               look_alike=np.zeros(len(searched), dtype=bool))


#: How far from the anchor's place a replaced pair's percept stands (metres, uniform up to this).
REPLACED_OFFSET = 0.05


def _replaced(chunk: PairChunk, config: PairDatasetConfig, scene_id: str) -> PairChunk:
    """Replaced copies of some of the scene's same-class false pairs, twins excepted: the percept
    stands where the anchor was (see the module docstring)."""
    rows = np.flatnonzero(~chunk.labels & (chunk.percept_classes == chunk.anchor_classes) & ~chunk.twins)
    revisits = chunk.labels & (chunk.percept_stamps - chunk.anchor_last_seen >= config.replaced_absence[0])
    count = min(int(round(config.replaced_pairs_per_revisit * int(revisits.sum()))), len(rows))
    if count == 0:
        return chunk.take(slice(0, 0))
    seed = int.from_bytes(hashlib.sha256(f"{config.seed}|replace|{scene_id}".encode()).digest()[:8], "little")
    rng = np.random.default_rng(seed)
    replaced = chunk.take(np.sort(rng.choice(rows, size=count, replace=False)))
    angle = rng.uniform(0.0, 2.0 * math.pi, size=count)
    offset = rng.uniform(0.0, REPLACED_OFFSET, size=count)
    positions = replaced.anchor_positions.copy()
    positions[:, 0] += offset * np.cos(angle)
    positions[:, 1] += offset * np.sin(angle)
    shortest, longest = config.replaced_absence
    absence = np.exp(rng.uniform(math.log(shortest), math.log(longest), size=count))
    return dataclasses.replace(replaced, percept_positions=positions,
                               anchor_last_seen=replaced.percept_stamps - absence,
                               replaced=np.ones(count, dtype=bool), look_alike=np.zeros(count, dtype=bool))


def _padded(ids: np.ndarray, width: int) -> np.ndarray:
    """(K, G) gallery ids padded with "" to (K, width)."""
    if ids.shape[1] == width:
        return ids
    padded = np.full((ids.shape[0], width), "", dtype=object)
    padded[:, : ids.shape[1]] = ids
    return padded


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
