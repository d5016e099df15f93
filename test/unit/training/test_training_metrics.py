"""The paper's table from a hand-made confusion matrix."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from merlin2_sailor.errors import InvalidInputError
from merlin2_sailor.training.metrics import (
    ConfusionCounts,
    ThresholdSweep,
    format_confusion,
    format_sweeps,
    format_table,
)
from merlin2_sailor.training.plots import plot_confusions, plot_curves, plot_threshold_sweeps


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

    confusion = plot_confusions(tmp_path / "c.png", {"a": ConfusionCounts(5, 1, 2, 50), "b": ConfusionCounts()})
    curves = plot_curves(tmp_path / "l.png", {"train": [0.5, 0.3, 0.2], "val": [0.6, float("nan"), 0.25]}, "loss")
    for path in (confusion, curves):
        image = cv2.imread(str(path))
        assert image is not None and image.shape[0] > 100


def test_a_sweep_gives_the_counts_of_any_threshold_of_its_grid_as_from_scores_does() -> None:
    """Streamed in two parts, read at thresholds the scores sit on, between and at the ends."""
    rng = np.random.default_rng(7)
    labels = rng.random(2000) < 0.2
    scores = np.round(np.where(labels, rng.beta(5, 2, 2000), rng.beta(2, 5, 2000)), 3)
    scores[:3] = (0.5, 1.0, 0.0)
    sweep = ThresholdSweep()
    sweep.add(labels[:700], scores[:700])
    rest = ThresholdSweep()
    rest.add(labels[700:], scores[700:])
    sweep = sweep + rest
    for threshold in (0.0, 0.25, 0.5, 0.731, 0.999, 1.0):
        assert sweep.at(threshold) == ConfusionCounts.from_scores(labels, scores, threshold), threshold


def test_the_best_threshold_separates_what_the_default_cut_does_not() -> None:
    """True pairs all at 0.8 and above, false ones at 0.6 and below: a cut at 0.5 keeps the false
    ones; the best cut lies between the two and scores F1 1."""
    labels = np.array([True] * 50 + [False] * 200)
    scores = np.concatenate([np.linspace(0.8, 1.0, 50), np.linspace(0.0, 0.6, 200)])
    sweep = ThresholdSweep()
    sweep.add(labels, scores)
    assert sweep.at(0.5).false_positives == int(np.sum(scores[50:] >= 0.5))
    threshold, best = sweep.best()
    assert 0.6 < threshold <= 0.8 and best.f1 == 1.0
    assert sweep.f1_curve()[int(round(threshold * sweep.bins))] == pytest.approx(1.0)
    line = format_sweeps({"network": sweep}, 0.5)
    assert f"best 1.0000 at {threshold:.3f}" in line and f"F1 {sweep.at(0.5).f1:.4f} at 0.500" in line


def test_a_sweep_refuses_what_it_cannot_count_and_an_empty_one_has_no_best() -> None:
    with pytest.raises(InvalidInputError):
        ThresholdSweep(bins=0)
    with pytest.raises(InvalidInputError):
        ThresholdSweep().add(np.array([True, False]), np.array([0.5]))
    with pytest.raises(InvalidInputError):
        ThresholdSweep(10) + ThresholdSweep(100)
    threshold, counts = ThresholdSweep().best()
    assert math.isnan(threshold) and counts.total == 0
    nan_and_out_of_range = ThresholdSweep()
    nan_and_out_of_range.add(np.array([True, False, True]), np.array([np.nan, -0.5, 1.7]))
    assert nan_and_out_of_range.at(0.5) == ConfusionCounts(1, 0, 1, 1)


def test_the_sweep_plot_is_a_png(tmp_path) -> None:
    sweep = ThresholdSweep()
    sweep.add(np.array([True, False, True, False]), np.array([0.9, 0.2, 0.7, 0.6]))
    path = plot_threshold_sweeps(tmp_path / "sweep.png", {"network": sweep, "rules": sweep}, 0.5)
    image = cv2.imread(str(path))
    assert image is not None and image.shape == (420, 720, 3)
    assert (image < 250).any(axis=2).sum() > 1000  # curves, axes and labels were drawn
