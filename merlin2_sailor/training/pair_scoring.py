"""Score streamed pair chunks with any matcher and tally the paper's metrics per pair subset.

The matchers are the anchoring layer's own (:class:`~merlin2_sailor.anchoring.rule_matcher.RuleMatcher`,
:class:`~merlin2_sailor.anchoring.matching_network.NetworkMatcher`), fed the features the
anchoring layer computes. One difference is counted apart: the anchoring layer never compares
a partial percept's look (a learned matcher then scores the pair by its fallback rules), while
the subsets score every pair with its look, as the network was trained; ``as_run`` scores the
pairs as the robot does.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable
from dataclasses import dataclass, field

from merlin2_sailor.anchoring.features import PairFeatures
from merlin2_sailor.anchoring.matcher import Matcher
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.training.embedding_cache import EmbeddingCache
from merlin2_sailor.training.metrics import ConfusionCounts, ThresholdSweep
from merlin2_sailor.training.pair_dataset import PairChunk


def chunk_features(chunk: PairChunk, matcher: Matcher, cache: EmbeddingCache | None) -> PairFeatures:
    """Features for ``matcher``: with appearance from ``cache`` when it uses appearance."""
    embeddings = None
    if matcher.uses_appearance:
        if cache is None:
            raise ConfigurationError("A matcher that uses appearance needs an embedding cache of the crops.")
        embeddings = chunk.embeddings(cache.lookup)
    return chunk.features(matcher.feature_config, embeddings)


def as_run(features: PairFeatures, chunk: PairChunk) -> PairFeatures:
    """The features as the anchoring layer hands them to its matcher: a partial percept's look is
    not compared (:func:`merlin2_sailor.anchoring.partial_view.comparable_views`), so a learned
    matcher scores that pair by its fallback rules."""
    return dataclasses.replace(features, appearance_known=features.appearance_known & ~chunk.percept_partial)


@dataclass(slots=True)
class PairEvaluation:
    """Confusion counts over every pair of Algorithm 3, over its look-alike pairs (same class,
    near) and its pairs where either side is a partial view (cut by the image's edge or an
    occluder; only a source that renders whole frames, such as the house source, knows); and,
    apart, over the searched pairs and the replaced pairs (:mod:`.pair_dataset`: appearance alone
    must tell). ``as_run``: every pair of Algorithm 3 again, scored as the anchoring layer scores
    it (:func:`as_run`); it differs from ``all_pairs`` only for a matcher that reads the look.
    ``all_pairs_sweep`` and ``as_run_sweep``: the same pairs' scores by label, for every threshold."""

    all_pairs: ConfusionCounts = field(default_factory=ConfusionCounts)
    look_alike: ConfusionCounts = field(default_factory=ConfusionCounts)
    partial: ConfusionCounts = field(default_factory=ConfusionCounts)
    searched: ConfusionCounts = field(default_factory=ConfusionCounts)
    replaced: ConfusionCounts = field(default_factory=ConfusionCounts)
    as_run: ConfusionCounts = field(default_factory=ConfusionCounts)
    all_pairs_sweep: ThresholdSweep = field(default_factory=ThresholdSweep)
    as_run_sweep: ThresholdSweep = field(default_factory=ThresholdSweep)


def evaluate_pairs(
    matcher: Matcher, chunks: Iterable[PairChunk], cache: EmbeddingCache | None, threshold: float = 0.5
) -> PairEvaluation:
    """Score every chunk with ``matcher`` and count, streaming."""
    result = PairEvaluation()
    for chunk in chunks:
        features = chunk_features(chunk, matcher, cache)
        scores = matcher.score_pairs(features)
        paper = ~(chunk.searched | chunk.replaced)
        scores_as_run = matcher.score_pairs(as_run(features, chunk)) if matcher.uses_appearance else scores
        result.as_run = result.as_run + ConfusionCounts.from_scores(chunk.labels[paper], scores_as_run[paper],
                                                                    threshold)
        result.all_pairs_sweep.add(chunk.labels[paper], scores[paper])
        result.as_run_sweep.add(chunk.labels[paper], scores_as_run[paper])
        subsets = (("all_pairs", paper), ("look_alike", chunk.look_alike & paper), ("partial", chunk.partial & paper),
                   ("searched", chunk.searched), ("replaced", chunk.replaced))
        for subset, mask in subsets:
            counts = ConfusionCounts.from_scores(chunk.labels[mask], scores[mask], threshold)
            setattr(result, subset, getattr(result, subset) + counts)
    return result
