"""The pair features of the matching function M, computed in one place, vectorised over pairs.

For a percept p and an anchor a the paper's M reads: same class (bool), the two crops'
appearance, the L2 distance of the positions, a scale factor of the sizes and the time between
them. They are encoded as the public implementation encodes them, except time:

- distance: ``exp(-d)`` in (0, 1], 1 at the same place, where ``d`` is the *footprint distance*:
  the distance between the centres less what a large object's extent explains (see
  :func:`extent_slack`). The public implementation feeds the plain distance; but the centre of a
  view is the middle of the part the camera saw, so two views of one television or bicycle are
  centred up to half its footprint apart, and a network fed the plain distance takes them for
  two objects (measured on a tour of the demo's house: of the 234 true pairs the version-1
  network rejected, 73 were under 0.1 m apart by footprint and over 0.2 m by centre);
- separation: ``exp(-r)`` in (0, 1], where ``r`` is the same distance in widths of the object
  along the line joining the two centres (the wider of the two boxes' extents along it, never
  below :data:`MINIMUM_SEPARATION_WIDTH`). A distance in metres does not say whether two views
  can be of one object: 0.2 m is the noise of one bicycle's centre and the gap between two
  clocks on a shelf. Two solid objects cannot stand nearer than about their width along the
  line between them, while the centre of one object's views moves by a fraction of it (plus the
  noise of depth and pose, hence the floor). Measured on the held-out houses before this feature
  (version 3 weights): the network's 138 false pairs were all same-class neighbours (rows of
  look-alikes 0.2 m apart, histogram intersections 0.9), at a median 0.94 widths, where three
  quarters of the true pairs were within 0.2 widths;
- scale: ``sum_i min(s_p_i, s_a_i) / sum_i max(s_p_i, s_a_i)`` in [0, 1], 1 for the same size;
- time: the original ``2 / (1 + exp(|dt|))`` is below 0.01 after 5.3 s, so an object seen a
  minute ago and one seen an hour ago look the same to the network. Here it is
  ``2 / (1 + exp(|dt| / time_scale))``: the same shape, stretched by a configurable time scale
  (``time_scale = 1`` reproduces the original exactly, so weights trained with it still apply);
- appearance: the element-wise L1 difference ``|f_p - f_a|`` of the frozen backbone's features,
  the siamese branch's input. An anchor keeps a gallery of recent features; the gallery entry
  nearest the percept (smallest L1 norm) is used, so an object is recognised from whichever side
  it was last seen. An embedding may end with the crop's colour and layout descriptor
  (:mod:`merlin2_sailor.perception.crop_descriptor`); its part of the difference is carried
  along, and the network reads it as similarities of its own.

- searched: 1 when the anchor is being searched for (an expectation with a radius): its distance
  is then measured from the searched disc, so anywhere in it is "here" and the place says
  nothing; the network must know, or it takes the green mug in the room searched for the red
  mug sought (in the house, same class and same place otherwise almost always mean the same object).

An anchor with an expected location (an action's predicted effect) is measured from whichever of
its expected and last perceived positions is nearer the percept: if the action failed and the
object is still where the camera last saw it, the percept is recognised as that object (and the
expectation retracted) instead of becoming a duplicate anchor.

:data:`FEATURE_ENCODING_VERSION` names this encoding; weights files record it, and a network is
never fed features encoded differently from those it was trained on.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.anchoring.anchor import Anchor
from merlin2_sailor.anchoring.gallery import from_bfloat16_bits
from merlin2_sailor.contract.percept import Percept
from merlin2_sailor.errors import ConfigurationError, InvalidInputError

#: Version of the encoding above; bump it whenever an encoding changes. 2: the distance score is
#: that of the footprint distance (1: of the plain distance), and the searched feature is new;
#: 3: embeddings end with the crop's colour descriptor (centre and surround histograms), compared
#: as a feature of its own; 4: the separation in object widths is new; 5: the crop descriptor
#: also holds a thumbnail of the crop's layout, read as two more similarities.
FEATURE_ENCODING_VERSION = 5

#: Pairs whose appearance is compared at once; bounds each (pairs, D) temporary to ~5 MB.
APPEARANCE_CHUNK_PAIRS = 1024


@dataclass(frozen=True, slots=True)
class FeatureConfig:
    """``time_scale`` (s): how fast the time feature decays; 0.5 at about 1.1 time scales."""

    time_scale: float = 30.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.time_scale) and self.time_scale > 0.0):
            raise ConfigurationError(f"feature time_scale must be a positive number of seconds, got {self.time_scale}.")


#: Objects whose footprint (longest horizontal side, metres) is at most this are matched by their
#: centres. A larger object's centre moves with the view (the near end of a bicycle seen end-on, a
#: television half out of the picture), by up to half of what exceeds this, so that much distance
#: between a percept and an anchor of it is forgiven in ``PairFeatures.footprint_distance`` (see
#: :func:`extent_slack`), which both matchers score (the network as ``distance_score``).
SMALL_OBJECT_EXTENT = 0.3


def extent_slack(sizes: np.ndarray) -> np.ndarray:
    """How far the centre of a partial view of an object of each (..., 3) size may lie from the
    centre of the whole: half of its footprint beyond :data:`SMALL_OBJECT_EXTENT`, else 0."""
    sizes = np.asarray(sizes, dtype=np.float64)
    footprint = np.max(sizes[..., :2], axis=-1)
    return np.maximum(footprint - SMALL_OBJECT_EXTENT, 0.0) / 2.0


def extent_slack_along(offsets: np.ndarray, sizes: np.ndarray) -> np.ndarray:
    """As :func:`extent_slack`, but of each box's extent along the horizontal ``offset`` (..., 3)
    between two centres (its longest horizontal side for a vertical or zero offset): a partial
    view's centre lies off its object's along the object, never farther across it than the object
    is wide. Forgiven in every direction, a side view of a bicycle, 1.6 m long, took 0.65 m of
    slack across its 0.35 m width, and scored 1.00 by place against the anchor of another bicycle
    standing 0.56 m beside it as against its own (scenario suite, `bicycle_wheeled_beside_another`,
    network, seed 0, 7 December 2026)."""
    return np.maximum(width_along(offsets, sizes) - SMALL_OBJECT_EXTENT, 0.0) / 2.0


def width_along(offsets: np.ndarray, sizes: np.ndarray) -> np.ndarray:
    """The width of each axis-aligned box of ``sizes`` (..., 3) along its horizontal ``offset``
    (..., 3); for a vertical or zero offset, its longest horizontal side."""
    offsets = np.asarray(offsets, dtype=np.float64)[..., :2]
    sizes = np.asarray(sizes, dtype=np.float64)[..., :2]
    length = np.linalg.norm(offsets, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        direction = np.abs(np.where(length > 1e-9, offsets / length, 0.0))
    return np.where(length[..., 0] > 1e-9, (direction * sizes).sum(axis=-1), sizes.max(axis=-1))


def encode_distance(distance: np.ndarray) -> np.ndarray:
    return np.exp(-np.asarray(distance, dtype=np.float64))


#: The narrowest width (metres) a separation is measured in. A view's centre is off by depth noise
#: and pose error whatever the object's size: on the held-out houses 90 % of the true pairs a frame
#: apart were within 0.09 m, of those a second or more apart within 0.14 m. Measured in its own 5 cm,
#: the cookbook of the demo's house seen again 0.14 m off after a minute was three widths away and
#: became a second anchor (a tour with world seed 2); a floor of 0.1 m still split it.
MINIMUM_SEPARATION_WIDTH = 0.15


def separation(offsets: np.ndarray, distances: np.ndarray, sizes_a: np.ndarray, sizes_b: np.ndarray) -> np.ndarray:
    """``distances`` in widths of the wider of two axis-aligned boxes along each horizontal
    ``offset`` (centre to centre); a vertical or zero offset is measured in the boxes' longest
    horizontal side."""
    widths = np.maximum(np.maximum(width_along(offsets, sizes_a), width_along(offsets, sizes_b)),
                        MINIMUM_SEPARATION_WIDTH)
    return np.asarray(distances, dtype=np.float64) / widths


def encode_time(time_difference: np.ndarray, time_scale: float) -> np.ndarray:
    # exp overflows to inf for huge |dt| / time_scale, and 2 / inf is the right limit: 0.
    with np.errstate(over="ignore"):
        return 2.0 / (1.0 + np.exp(np.abs(np.asarray(time_difference, dtype=np.float64)) / time_scale))


def scale_factor(sizes_a: np.ndarray, sizes_b: np.ndarray) -> np.ndarray:
    """Similarity of (..., 3) sizes; two zero sizes count as equal (1.0)."""
    sizes_a = np.asarray(sizes_a, dtype=np.float64)
    sizes_b = np.asarray(sizes_b, dtype=np.float64)
    smaller = np.minimum(sizes_a, sizes_b).sum(axis=-1)
    larger = np.maximum(sizes_a, sizes_b).sum(axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(larger > 0.0, smaller / larger, 1.0)


@dataclass(frozen=True, slots=True, eq=False)
class PerceptColumns:
    """The percepts of one frame as arrays; ``embeddings`` rows are valid where ``has_embedding``."""

    class_names: np.ndarray  # (P,) str
    positions: np.ndarray  # (P, 3)
    sizes: np.ndarray  # (P, 3)
    stamps: np.ndarray  # (P,)
    tracker_ids: np.ndarray  # (P,) str
    embeddings: np.ndarray | None  # (P, D) float32
    has_embedding: np.ndarray  # (P,) bool

    @classmethod
    def from_percepts(cls, percepts: Sequence[Percept]) -> PerceptColumns:
        count = len(percepts)
        dimensions = {p.embedding.shape[-1] for p in percepts if p.embedding is not None}
        if len(dimensions) > 1:
            raise InvalidInputError(f"Percepts of one frame carry embeddings of different sizes {sorted(dimensions)}.")
        embeddings = None
        has_embedding = np.array([p.embedding is not None for p in percepts], dtype=bool)
        if dimensions:
            embeddings = np.zeros((count, dimensions.pop()), dtype=np.float32)
            for row, percept in enumerate(percepts):
                if percept.embedding is not None:
                    embeddings[row] = percept.embedding
        return cls(
            class_names=np.array([p.class_name for p in percepts], dtype=object),
            positions=np.array([p.position for p in percepts], dtype=np.float64).reshape(count, 3),
            sizes=np.array([p.size for p in percepts], dtype=np.float64).reshape(count, 3),
            stamps=np.array([p.stamp for p in percepts], dtype=np.float64),
            tracker_ids=np.array([p.tracker_id for p in percepts], dtype=object),
            embeddings=embeddings,
            has_embedding=has_embedding,
        )


@dataclass(frozen=True, slots=True, eq=False)
class AnchorColumns:
    """Anchors as arrays; galleries padded to a common length, valid up to ``gallery_lengths``."""

    class_names: np.ndarray  # (A,) str
    positions: np.ndarray  # (A, 3)
    sizes: np.ndarray  # (A, 3)
    last_seen: np.ndarray  # (A,)
    tracker_ids: np.ndarray  # (A,) str
    galleries: np.ndarray | None  # (A, G, D) bfloat16 bits
    gallery_lengths: np.ndarray  # (A,) int
    perceived_positions: np.ndarray | None = None  # (A, 3), only when some anchor has an expectation
    search_radii: np.ndarray | None = None  # (A,), only when some anchor is being searched for

    @classmethod
    def from_anchors(cls, anchors: Sequence[Anchor]) -> AnchorColumns:
        count = len(anchors)
        with_gallery = [a.gallery for a in anchors if a.gallery is not None and len(a.gallery)]
        lengths = np.array([0 if a.gallery is None else len(a.gallery) for a in anchors], dtype=np.intp)
        galleries = None
        if with_gallery:
            dimension = with_gallery[0].shape[1]
            galleries = np.zeros((count, int(lengths.max()), dimension), dtype=with_gallery[0].dtype)
            for row, anchor in enumerate(anchors):
                if lengths[row]:
                    galleries[row, : lengths[row]] = anchor.gallery
        perceived = None
        if any(anchor.expectation is not None for anchor in anchors):
            perceived = np.array(
                [a.position if a.expectation is None else a.perceived_position for a in anchors], dtype=np.float64
            ).reshape(count, 3)
        radii = np.array([0.0 if a.expectation is None else a.expectation.radius for a in anchors], dtype=np.float64)
        return cls(
            class_names=np.array([a.class_name for a in anchors], dtype=object),
            positions=np.array([a.position for a in anchors], dtype=np.float64).reshape(count, 3),
            sizes=np.array([a.size for a in anchors], dtype=np.float64).reshape(count, 3),
            last_seen=np.array([a.last_seen for a in anchors], dtype=np.float64),
            tracker_ids=np.array([a.last_tracker_id for a in anchors], dtype=object),
            galleries=galleries,
            gallery_lengths=lengths,
            perceived_positions=perceived,
            search_radii=radii if np.any(radii > 0.0) else None,
        )


@dataclass(frozen=True, slots=True, eq=False)
class PairFeatures:
    """Features of K (percept, anchor) pairs, both raw (for rules) and encoded (for the network).

    ``rows`` / ``columns`` index the percepts / anchors the pairs came from. ``appearance_difference``
    is None when appearance was not asked for; otherwise its rows are valid where
    ``appearance_known`` (both sides had an embedding) and zero elsewhere.
    """

    rows: np.ndarray
    columns: np.ndarray
    same_class: np.ndarray  # (K,) bool
    distance: np.ndarray  # (K,) metres
    footprint_distance: np.ndarray  # (K,) metres, less what a large object's extent explains
    place_distance: np.ndarray  # (K,) metres, less what its extent along the line between them explains
    distance_score: np.ndarray  # (K,) exp(-footprint_distance)
    separation: np.ndarray  # (K,) the distance in object widths along the line between the centres
    separation_score: np.ndarray  # (K,) exp(-separation)
    scale: np.ndarray  # (K,)
    time_difference: np.ndarray  # (K,) seconds, percept stamp minus anchor last seen
    time_score: np.ndarray  # (K,)
    searched: np.ndarray  # (K,) bool: the anchor is searched for, its distance measured from the disc
    appearance_known: np.ndarray  # (K,) bool
    appearance_distance: np.ndarray  # (K,) L1 norm of appearance_difference, NaN where unknown
    appearance_difference: np.ndarray | None  # (K, D) float32

    def __len__(self) -> int:
        return len(self.rows)


def pair_features(
    percepts: PerceptColumns,
    anchors: AnchorColumns,
    rows: np.ndarray,
    columns: np.ndarray,
    config: FeatureConfig,
    with_appearance: bool,
) -> PairFeatures:
    """Compute the features of the pairs (``rows[k]``, ``columns[k]``) in one vectorised pass."""
    rows = np.asarray(rows, dtype=np.intp)
    columns = np.asarray(columns, dtype=np.intp)
    offsets = percepts.positions[rows] - anchors.positions[columns]
    distance = np.linalg.norm(offsets, axis=1)
    searched = np.zeros(len(rows), dtype=bool)
    if anchors.search_radii is not None:  # anywhere in a searched disc is as good as its centre
        distance = np.maximum(distance - anchors.search_radii[columns], 0.0)
        searched = anchors.search_radii[columns] > 0.0
    if anchors.perceived_positions is not None:
        perceived_distance = np.linalg.norm(percepts.positions[rows] - anchors.perceived_positions[columns], axis=1)
        distance = np.minimum(distance, perceived_distance)
    # Two views of one large object need not share a centre: forgive what its extent explains.
    slack = np.maximum(extent_slack(percepts.sizes[rows]), extent_slack(anchors.sizes[columns]))
    footprint_distance = np.maximum(distance - slack, 0.0)
    slack_along = np.maximum(extent_slack_along(offsets, percepts.sizes[rows]),
                             extent_slack_along(offsets, anchors.sizes[columns]))
    place_distance = np.maximum(distance - slack_along, 0.0)
    widths_apart = separation(offsets, distance, percepts.sizes[rows], anchors.sizes[columns])
    time_difference = percepts.stamps[rows] - anchors.last_seen[columns]
    known = np.zeros(len(rows), dtype=bool)
    appearance_distance = np.full(len(rows), np.nan)
    difference = None
    if with_appearance and percepts.embeddings is not None and anchors.galleries is not None:
        known = percepts.has_embedding[rows] & (anchors.gallery_lengths[columns] > 0)
        difference = np.zeros((len(rows), percepts.embeddings.shape[1]), dtype=np.float32)
        appearance_distance[known] = _nearest_gallery_difference(
            percepts, anchors, rows[known], columns[known], difference, known
        )
    elif with_appearance:
        dimension = percepts.embeddings.shape[1] if percepts.embeddings is not None else (
            anchors.galleries.shape[2] if anchors.galleries is not None else 0
        )
        difference = np.zeros((len(rows), dimension), dtype=np.float32)
    return PairFeatures(
        rows=rows,
        columns=columns,
        same_class=percepts.class_names[rows] == anchors.class_names[columns],
        distance=distance,
        footprint_distance=footprint_distance,
        place_distance=place_distance,
        distance_score=encode_distance(footprint_distance),
        separation=widths_apart,
        separation_score=encode_distance(widths_apart),
        scale=scale_factor(percepts.sizes[rows], anchors.sizes[columns]),
        time_difference=time_difference,
        time_score=encode_time(time_difference, config.time_scale),
        searched=searched,
        appearance_known=known,
        appearance_distance=appearance_distance,
        appearance_difference=difference,
    )


def _nearest_gallery_difference(
    percepts: PerceptColumns,
    anchors: AnchorColumns,
    rows: np.ndarray,
    columns: np.ndarray,
    out: np.ndarray,
    known: np.ndarray,
) -> np.ndarray:
    """Fill ``out[known]`` with |f_p - g| for each pair's nearest gallery entry g; return the L1 norms.

    Gallery entries are visited one at a time, keeping the best so far, so the temporaries are
    (pairs, D) rather than (pairs, gallery, D): they stay in cache, which makes this ~3x faster.
    """
    assert percepts.embeddings is not None and anchors.galleries is not None
    if percepts.embeddings.shape[1] != anchors.galleries.shape[2]:
        raise InvalidInputError(
            f"Percept embeddings have {percepts.embeddings.shape[1]} dimensions but anchor galleries "
            f"{anchors.galleries.shape[2]}; one backbone must embed both."
        )
    targets = np.flatnonzero(known)
    norms = np.empty(len(rows))
    for start in range(0, len(rows), APPEARANCE_CHUNK_PAIRS):
        chunk = slice(start, start + APPEARANCE_CHUNK_PAIRS)
        features = percepts.embeddings[rows[chunk]]
        lengths = anchors.gallery_lengths[columns[chunk]]
        best = np.full(len(features), np.inf)
        best_difference = np.zeros_like(features)
        for entry in range(anchors.galleries.shape[1]):
            difference = np.abs(features - from_bfloat16_bits(anchors.galleries[columns[chunk], entry]))
            l1 = difference.sum(axis=1, dtype=np.float64)
            better = (l1 < best) & (entry < lengths)
            best[better] = l1[better]
            best_difference[better] = difference[better]
        out[targets[chunk]] = best_difference
        norms[chunk] = best
    return norms
