"""Score streamed pair chunks with any matcher and tally the paper's metrics per pair subset.

The matchers are the anchoring layer's own (:class:`~merlin2_sailor.anchoring.rule_matcher.RuleMatcher`,
:class:`~merlin2_sailor.anchoring.matching_network.NetworkMatcher`), fed the features the
anchoring layer computes, so an evaluation measures exactly what runs on the robot.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

from merlin2_sailor.anchoring.features import PairFeatures
from merlin2_sailor.anchoring.matcher import Matcher
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.training.embedding_cache import EmbeddingCache
from merlin2_sailor.training.metrics import ConfusionCounts
from merlin2_sailor.training.pair_dataset import PairChunk


def chunk_features(chunk: PairChunk, matcher: Matcher, cache: EmbeddingCache | None) -> PairFeatures:
    """Features for ``matcher``: with appearance from ``cache`` when it uses appearance."""
    embeddings = None
    if matcher.uses_appearance:
        if cache is None:
            raise ConfigurationError("A matcher that uses appearance needs an embedding cache of the crops.")
        embeddings = (cache.lookup(chunk.percept_crop_ids), cache.lookup(chunk.anchor_crop_ids))
    return chunk.features(matcher.feature_config, embeddings)


@dataclass(slots=True)
class PairEvaluation:
    """Confusion counts over every pair and over the look-alike pairs (same class, near)."""

    all_pairs: ConfusionCounts = field(default_factory=ConfusionCounts)
    look_alike: ConfusionCounts = field(default_factory=ConfusionCounts)


def evaluate_pairs(
    matcher: Matcher, chunks: Iterable[PairChunk], cache: EmbeddingCache | None, threshold: float = 0.5
) -> PairEvaluation:
    """Score every chunk with ``matcher`` and count, streaming."""
    result = PairEvaluation()
    for chunk in chunks:
        scores = matcher.score_pairs(chunk_features(chunk, matcher, cache))
        result.all_pairs += ConfusionCounts.from_scores(chunk.labels, scores, threshold)
        mask = chunk.look_alike
        result.look_alike += ConfusionCounts.from_scores(chunk.labels[mask], scores[mask], threshold)
    return result
