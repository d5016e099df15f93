"""The paper's table from a hand-made confusion matrix."""

from __future__ import annotations

import math

import numpy as np
import pytest

from merlin2_sailor.errors import InvalidInputError
from merlin2_sailor.training.metrics import ConfusionCounts, format_confusion, format_table
from merlin2_sailor.training.plots import plot_confusions, plot_curves


def test_metrics_of_a_hand_made_confusion() -> None:
    counts = ConfusionCounts(true_positives=90, false_positives=10, false_negatives=30, true_negatives=870)
    assert counts.total == 1000 and counts.positives == 120
    assert counts.accuracy == pytest.approx(0.96)
    assert counts.precision == pytest.approx(0.9)
    assert counts.recall == pytest.approx(0.75)
    assert counts.f1 == pytest.approx(2 * 0.9 * 0.75 / (0.9 + 0.75))
    table = format_table({"network": counts})
    assert "0.9600" in table and "0.9000" in table and "0.7500" in table and "0.8182" in table
    assert "90" in format_confusion("network", counts)


def test_counts_from_scores_use_the_threshold_inclusively() -> None:
    labels = np.array([True, True, False, False, True])
    scores = np.array([0.5, 0.49, 0.5, 0.1, 0.9])
    assert ConfusionCounts.from_scores(labels, scores) == ConfusionCounts(2, 1, 1, 1)
    assert ConfusionCounts(1, 0, 0, 0) + ConfusionCounts(0, 2, 3, 4) == ConfusionCounts(1, 2, 3, 4)


def test_undefined_ratios_are_nan_not_perfect() -> None:
    counts = ConfusionCounts(true_negatives=5)
    assert math.isnan(counts.precision) and math.isnan(counts.recall) and counts.accuracy == 1.0
    with pytest.raises(InvalidInputError):
        ConfusionCounts(-1, 0, 0, 0)


def test_plots_are_written_as_png(tmp_path) -> None:
    import cv2

    confusion = plot_confusions(tmp_path / "c.png", {"a": ConfusionCounts(5, 1, 2, 50), "b": ConfusionCounts()})
    curves = plot_curves(tmp_path / "l.png", {"train": [0.5, 0.3, 0.2], "val": [0.6, float("nan"), 0.25]}, "loss")
    for path in (confusion, curves):
        image = cv2.imread(str(path))
        assert image is not None and image.shape[0] > 100
