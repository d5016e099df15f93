"""The paper's pair metrics: a confusion matrix and accuracy, precision, recall, F1.

A pair scored at or above the threshold (0.5, the anchoring layer's reacquire threshold) is
predicted "same instance". Undefined ratios (no predicted or no actual positives) are reported
as NaN rather than 0 or 1: a table must not claim a perfect precision nobody measured.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from merlin2_sailor.errors import InvalidInputError


def _ratio(numerator: int, denominator: int) -> float:
    return numerator / denominator if denominator else math.nan


@dataclass(frozen=True, slots=True)
class ConfusionCounts:
    """Counts of a binary decision: true / false positives / negatives."""

    true_positives: int = 0
    false_positives: int = 0
    false_negatives: int = 0
    true_negatives: int = 0

    def __post_init__(self) -> None:
        if min(self.true_positives, self.false_positives, self.false_negatives, self.true_negatives) < 0:
            raise InvalidInputError(f"confusion counts must not be negative: {self}.")

    @classmethod
    def from_scores(cls, labels: np.ndarray, scores: np.ndarray, threshold: float = 0.5) -> ConfusionCounts:
        labels = np.asarray(labels, dtype=bool)
        predicted = np.asarray(scores, dtype=np.float64) >= threshold
        if labels.shape != predicted.shape:
            raise InvalidInputError(f"{labels.shape[0]} labels but {predicted.shape[0]} scores.")
        return cls(
            true_positives=int(np.sum(labels & predicted)),
            false_positives=int(np.sum(~labels & predicted)),
            false_negatives=int(np.sum(labels & ~predicted)),
            true_negatives=int(np.sum(~labels & ~predicted)),
        )

    def __add__(self, other: ConfusionCounts) -> ConfusionCounts:
        return ConfusionCounts(
            self.true_positives + other.true_positives,
            self.false_positives + other.false_positives,
            self.false_negatives + other.false_negatives,
            self.true_negatives + other.true_negatives,
        )

    @property
    def total(self) -> int:
        return self.true_positives + self.false_positives + self.false_negatives + self.true_negatives

    @property
    def positives(self) -> int:
        return self.true_positives + self.false_negatives

    @property
    def accuracy(self) -> float:
        return _ratio(self.true_positives + self.true_negatives, self.total)

    @property
    def precision(self) -> float:
        return _ratio(self.true_positives, self.true_positives + self.false_positives)

    @property
    def recall(self) -> float:
        return _ratio(self.true_positives, self.positives)

    @property
    def f1(self) -> float:
        return _ratio(2 * self.true_positives, 2 * self.true_positives + self.false_positives + self.false_negatives)

    def as_dict(self) -> dict[str, float | int]:
        return {
            "pairs": self.total,
            "positives": self.positives,
            "true_positives": self.true_positives,
            "false_positives": self.false_positives,
            "false_negatives": self.false_negatives,
            "true_negatives": self.true_negatives,
            "accuracy": self.accuracy,
            "precision": self.precision,
            "recall": self.recall,
            "f1": self.f1,
        }


def format_table(rows: Mapping[str, ConfusionCounts]) -> str:
    """The paper's table (accuracy, precision, recall, F1), one row per named pair set / matcher."""
    width = max([len(name) for name in rows] + [8])
    header = f"{'':<{width}}  {'pairs':>9} {'positive':>9} {'accuracy':>9} {'precision':>9} {'recall':>9} {'F1':>9}"
    lines = [header]
    for name, counts in rows.items():
        lines.append(
            f"{name:<{width}}  {counts.total:>9d} {counts.positives:>9d} {counts.accuracy:>9.4f} "
            f"{counts.precision:>9.4f} {counts.recall:>9.4f} {counts.f1:>9.4f}"
        )
    return "\n".join(lines)


def format_confusion(name: str, counts: ConfusionCounts) -> str:
    """The confusion matrix as text: rows are the truth, columns the prediction."""
    return "\n".join(
        [
            f"{name}: rows = truth, columns = prediction",
            f"{'':<14}{'same':>10}{'different':>11}",
            f"{'same':<14}{counts.true_positives:>10d}{counts.false_negatives:>11d}",
            f"{'different':<14}{counts.false_positives:>10d}{counts.true_negatives:>11d}",
        ]
    )


@dataclass(slots=True)
class ThresholdSweep:
    """Pair scores binned by label, so the confusion counts at any threshold of a grid are read
    after one streamed pass.

    Why: one threshold's F1 mixes two questions, whether true and false pairs are scored apart at
    all, and where the cut between them is put. The matching network is trained to favour recall
    (``positive_weight``: a missed pair makes a duplicate anchor), so its cut is placed for the
    anchoring layer, not for the pair table; the best F1 over thresholds says how much of the
    table's shortfall is the cut's. Thresholds lie on a grid of ``1 / bins``; a score of exactly a
    grid value counts as reaching it (the anchoring layer's ``>=``).
    """

    bins: int = 1000
    positives: np.ndarray = field(default=None)  # type: ignore[assignment]
    negatives: np.ndarray = field(default=None)  # type: ignore[assignment]

    def __post_init__(self) -> None:
        if self.bins < 1:
            raise InvalidInputError(f"a threshold sweep needs at least one bin, got {self.bins}.")
        if self.positives is None:
            self.positives = np.zeros(self.bins + 1, dtype=np.int64)
        if self.negatives is None:
            self.negatives = np.zeros(self.bins + 1, dtype=np.int64)

    def add(self, labels: np.ndarray, scores: np.ndarray) -> None:
        """Count more pairs (a score outside [0, 1] or NaN counts as the nearest end, NaN as 0)."""
        labels = np.asarray(labels, dtype=bool)
        scores = np.nan_to_num(np.asarray(scores, dtype=np.float64), nan=0.0)
        if labels.shape != scores.shape:
            raise InvalidInputError(f"{labels.shape[0]} labels but {scores.shape[0]} scores.")
        index = np.clip(np.floor(scores * self.bins + 1e-9), 0, self.bins).astype(np.int64)
        self.positives += np.bincount(index[labels], minlength=self.bins + 1)
        self.negatives += np.bincount(index[~labels], minlength=self.bins + 1)

    def __add__(self, other: ThresholdSweep) -> ThresholdSweep:
        if other.bins != self.bins:
            raise InvalidInputError(f"threshold sweeps of {self.bins} and {other.bins} bins cannot be added.")
        return ThresholdSweep(self.bins, self.positives + other.positives, self.negatives + other.negatives)

    def at(self, threshold: float) -> ConfusionCounts:
        """The counts with pairs scored at or above ``threshold`` (rounded to the grid) taken as same."""
        first = int(np.clip(round(threshold * self.bins), 0, self.bins))
        true_positives, false_positives = int(self.positives[first:].sum()), int(self.negatives[first:].sum())
        return ConfusionCounts(true_positives, false_positives, int(self.positives.sum()) - true_positives,
                               int(self.negatives.sum()) - false_positives)

    def thresholds(self) -> np.ndarray:
        return np.arange(self.bins + 1, dtype=np.float64) / self.bins

    def f1_curve(self) -> np.ndarray:
        """F1 at every threshold of the grid (NaN where nothing is predicted or present)."""
        true_positives = np.cumsum(self.positives[::-1])[::-1].astype(np.float64)
        false_positives = np.cumsum(self.negatives[::-1])[::-1].astype(np.float64)
        false_negatives = float(self.positives.sum()) - true_positives
        denominator = 2 * true_positives + false_positives + false_negatives
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(denominator > 0, 2 * true_positives / denominator, np.nan)

    def best(self) -> tuple[float, ConfusionCounts]:
        """The threshold of the grid with the highest F1 (ties: the lowest), and its counts."""
        curve = self.f1_curve()
        if not np.isfinite(curve).any():
            return math.nan, self.at(0.0)
        threshold = float(self.thresholds()[int(np.nanargmax(curve))])
        return threshold, self.at(threshold)


def format_sweeps(rows: Mapping[str, ThresholdSweep], threshold: float) -> str:
    """One line per named sweep: F1 at ``threshold`` (the anchoring layer's) and the best over the grid."""
    width = max([len(name) for name in rows] + [8])
    lines = []
    for name, sweep in rows.items():
        best_threshold, best = sweep.best()
        lines.append(f"{name:<{width}}  F1 {sweep.at(threshold).f1:.4f} at {threshold:.3f}; best {best.f1:.4f} at "
                     f"{best_threshold:.3f} (precision {best.precision:.4f}, recall {best.recall:.4f}, "
                     f"{best.false_positives} false, {best.false_negatives} missed)")
    return "\n".join(lines)
