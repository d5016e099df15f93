"""How a reacquired anchor absorbs a new percept: filter, vote and remember; never overwrite.

A single percept is noisy (depth noise, a box cut by the image border, a misclassification), so
overwriting an anchor with its latest percept makes symbols jitter and flip. Each attribute is
filtered by the rule that fits its noise:

- position: a scalar Kalman filter with a random-walk model (inverse-variance weighting). The
  variance grows while the anchor is unseen, because an object seen long ago may have moved, so a
  fresh measurement then counts for more; a static object seen many times barely moves.
- size: an exponential moving average whose weight starts at 1/times_seen (a plain mean of the
  first measurements), then stays at ``size_smoothing``, so size can still follow a real change.
- class: votes weighted by detector score; one misdetection cannot flip the class.
- appearance: a gallery of ``gallery_size`` embeddings (:mod:`.gallery`), so the object is
  recognised from any side it was seen from recently; a new view replaces the one nearest it in
  size, so close views survive the far ones seen while the robot drives away.

These are pure functions of arrays and numbers: the state lives on the anchor.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.errors import ConfigurationError


@dataclass(frozen=True, slots=True)
class FusionConfig:
    """``measurement_variance`` (m^2): a percept position's noise (0.01 = 10 cm standard deviation).
    ``drift_variance_rate`` (m^2/s): how fast uncertainty about an unseen anchor's position grows.
    ``initial_variance`` (m^2): the variance of a newly acquired anchor's position.
    ``size_smoothing``: the weight of a new size measurement once the anchor is well known.
    ``gallery_size``: how many views' embeddings an anchor keeps.
    ``partial_view_variance_factor``: how many times less a partial view (cut by the image's edge or
    an occluder, see :mod:`.partial_view`) moves an anchor than a whole one; its centre and size
    are those of the part in view."""

    measurement_variance: float = 0.01
    drift_variance_rate: float = 0.01
    initial_variance: float = 0.01
    size_smoothing: float = 0.2
    gallery_size: int = 4
    partial_view_variance_factor: float = 100.0

    def __post_init__(self) -> None:
        for name in ("measurement_variance", "initial_variance"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise ConfigurationError(f"fusion {name} must be a positive number of m^2, got {value}.")
        if not (math.isfinite(self.drift_variance_rate) and self.drift_variance_rate >= 0.0):
            raise ConfigurationError(
                f"fusion drift_variance_rate must be >= 0 m^2/s, got {self.drift_variance_rate}."
            )
        if not (0.0 < self.size_smoothing <= 1.0):
            raise ConfigurationError(f"fusion size_smoothing must be in (0, 1], got {self.size_smoothing}.")
        if not (math.isfinite(self.partial_view_variance_factor) and self.partial_view_variance_factor >= 1.0):
            raise ConfigurationError(
                f"fusion partial_view_variance_factor must be at least 1, got {self.partial_view_variance_factor}."
            )
        if self.gallery_size < 1:
            raise ConfigurationError(f"fusion gallery_size must be at least 1, got {self.gallery_size}.")


def fuse_position(
    position: np.ndarray,
    variance: float,
    measurement: np.ndarray,
    elapsed: float,
    config: FusionConfig,
    partial: bool = False,
) -> tuple[np.ndarray, float]:
    """Return the fused (position, variance) after ``elapsed`` seconds unseen and one measurement
    (``partial``: of a partial view, trusted ``partial_view_variance_factor`` times less)."""
    predicted_variance = variance + config.drift_variance_rate * max(0.0, elapsed)
    measurement_variance = config.measurement_variance * (config.partial_view_variance_factor if partial else 1.0)
    gain = predicted_variance / (predicted_variance + measurement_variance)
    fused = position + gain * (np.asarray(measurement, dtype=np.float64) - position)
    return fused, (1.0 - gain) * predicted_variance


def fuse_size(size: np.ndarray, measurement: np.ndarray, times_seen: int, config: FusionConfig) -> np.ndarray:
    """Blend a size measurement in; ``times_seen`` counts this measurement too."""
    weight = max(1.0 / max(times_seen, 1), config.size_smoothing)
    return (1.0 - weight) * size + weight * np.asarray(measurement, dtype=np.float64)


def vote_class(votes: Mapping[str, float], class_name: str, score: float) -> dict[str, float]:
    """Add a detection's score to its class's votes; scores below a small floor still count."""
    updated = dict(votes)
    updated[class_name] = updated.get(class_name, 0.0) + max(float(score), 1e-3)
    return updated


def winning_class(votes: Mapping[str, float], current: str) -> str:
    """The class with most votes; the current class wins ties, so a tie never flips the symbol's class."""
    best = max(votes.values())
    return current if votes.get(current, -1.0) >= best else max(votes, key=votes.__getitem__)

