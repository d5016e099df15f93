"""A hand-tuned matching function: same class, close enough for the time elapsed.

An untrained network scores noise, so the anchoring layer needs a matcher that works out of the
box; this one is also the baseline the trained network is compared against. It ignores
appearance on purpose (no backbone, no torch): two identical mugs a metre apart are told apart
by position, which is what the rule encodes.

score = same_class * exp(-0.5 * (d / sigma)^2),  sigma = min(position_sigma + drift_speed * |dt|, maximum_sigma)

where d is the distance between the centres, less what a large object's extent *along the line
between them* explains (a part of a bicycle is centred up to 0.65 m from its middle, along it;
never farther across it than it is wide: ``features.extent_slack_along``). The network reads the
distance less the extent in any direction (``footprint_distance``), as it was trained.

``sigma`` grows with the time since the anchor was last seen, because an object unseen for a
while may have been moved a little; with the defaults a fresh pair scores 0.5 at 0.35 m.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from merlin2_sailor.anchoring.features import FeatureConfig, PairFeatures
from merlin2_sailor.anchoring.matcher import Matcher
from merlin2_sailor.errors import ConfigurationError


@dataclass(frozen=True, slots=True)
class RuleMatcherConfig:
    """``position_sigma`` (m): distance tolerance for a pair seen at the same time;
    ``drift_speed`` (m/s): how fast it widens with the time between them; ``maximum_sigma`` (m):
    its cap, so an anchor unseen for hours does not match anything in the room."""

    position_sigma: float = 0.3
    drift_speed: float = 0.02
    maximum_sigma: float = 1.0
    features: FeatureConfig = field(default_factory=FeatureConfig)

    def __post_init__(self) -> None:
        for name in ("position_sigma", "maximum_sigma"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise ConfigurationError(f"rule matcher {name} must be a positive number of metres, got {value}.")
        if not (math.isfinite(self.drift_speed) and self.drift_speed >= 0.0):
            raise ConfigurationError(f"rule matcher drift_speed must be >= 0 m/s, got {self.drift_speed}.")
        if self.maximum_sigma < self.position_sigma:
            raise ConfigurationError(
                f"rule matcher maximum_sigma ({self.maximum_sigma}) must not be below position_sigma "
                f"({self.position_sigma})."
            )


class RuleMatcher(Matcher):
    """Class, distance and time; no appearance (see the module docstring)."""

    uses_appearance = False

    def __init__(self, config: RuleMatcherConfig | None = None) -> None:
        self.config = config or RuleMatcherConfig()

    @property
    def feature_config(self) -> FeatureConfig:
        return self.config.features

    def score_pairs(self, features: PairFeatures) -> np.ndarray:
        sigma = np.minimum(
            self.config.position_sigma + self.config.drift_speed * np.abs(features.time_difference),
            self.config.maximum_sigma,
        )
        closeness = np.exp(-0.5 * (features.place_distance / sigma) ** 2)
        return np.where(features.same_class, closeness, 0.0)
