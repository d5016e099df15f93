"""The paper's pair metrics: a confusion matrix and accuracy, precision, recall, F1.

A pair scored at or above the threshold (0.5, the anchoring layer's reacquire threshold) is
predicted "same instance". Undefined ratios (no predicted or no actual positives) are reported
as NaN rather than 0 or 1: a table must not claim a perfect precision nobody measured.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

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
