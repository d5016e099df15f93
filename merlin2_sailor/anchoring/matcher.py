"""The matching function M behind one interface: ``score(percepts, anchors) -> (P, A) table``.

Two implementations: :class:`~.rule_matcher.RuleMatcher` (hand-tuned, no appearance, no torch)
and the paper's network, run in torch (:class:`~.matching_network.NetworkMatcher`) or exported
to OpenVINO (:class:`~.openvino_matcher.OpenVinoNetworkMatcher`). Both score *pairs* from
:class:`~.features.PairFeatures`, so the matching table can compute features once, for the pairs
that survive gating only, and hand them to whichever matcher is configured.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence

import numpy as np

from merlin2_sailor.anchoring.anchor import Anchor
from merlin2_sailor.anchoring.features import AnchorColumns, FeatureConfig, PairFeatures, PerceptColumns, pair_features
from merlin2_sailor.contract.percept import Percept


class Matcher(ABC):
    """Scores (percept, anchor) pairs with the probability that both are the same object."""

    #: Whether scores depend on appearance; if so, the matching table embeds crops it needs.
    uses_appearance: bool = False

    @property
    def threads(self) -> int:
        """Threads the matcher's network runs with (0: no network, or it does not say)."""
        return 0

    @property
    @abstractmethod
    def feature_config(self) -> FeatureConfig:
        """How this matcher expects features to be encoded."""

    @abstractmethod
    def score_pairs(self, features: PairFeatures) -> np.ndarray:
        """Return a (K,) float64 array in [0, 1], one score per pair of ``features``."""

    def score(self, percepts: Sequence[Percept], anchors: Sequence[Anchor]) -> np.ndarray:
        """Return the (P, A) table of M over every pair, without gating or tracker evidence.

        Percepts need their ``embedding`` set for an appearance matcher to use appearance.
        """
        rows, columns = np.indices((len(percepts), len(anchors))).reshape(2, -1)
        features = pair_features(
            PerceptColumns.from_percepts(percepts),
            AnchorColumns.from_anchors(anchors),
            rows,
            columns,
            self.feature_config,
            with_appearance=self.uses_appearance,
        )
        return self.score_pairs(features).reshape(len(percepts), len(anchors))
