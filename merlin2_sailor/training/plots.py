"""PNG plots drawn with OpenCV: the loss curves, the confusion matrices and pair F1 against the threshold.

matplotlib is not a dependency of this package; OpenCV (already one, for crops) draws lines,
rectangles and text well enough for two small figures.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path

import cv2
import numpy as np

from merlin2_sailor.training.metrics import ConfusionCounts, ThresholdSweep

_WHITE = (255, 255, 255)
_BLACK = (0, 0, 0)
_GREY = (200, 200, 200)
_COLOURS = ((200, 90, 30), (40, 130, 230), (60, 160, 60), (150, 60, 170))  # BGR
_FONT = cv2.FONT_HERSHEY_SIMPLEX


def _text(image: np.ndarray, text: str, origin: tuple[int, int], scale: float = 0.45, colour=_BLACK) -> None:
    cv2.putText(image, text, origin, _FONT, scale, colour, 1, cv2.LINE_AA)


def plot_curves(path: str | Path, curves: Mapping[str, Sequence[float]], title: str, x_label: str = "epoch") -> Path:
    """Line plot of named series against their index (1-based), written as PNG."""
    width, height, left, right, top, bottom = 720, 420, 70, 20, 40, 50
    image = np.full((height, width, 3), 255, dtype=np.uint8)
    values = np.array([v for series in curves.values() for v in series if np.isfinite(v)], dtype=np.float64)
    low, high = (float(values.min()), float(values.max())) if values.size else (0.0, 1.0)
    if high - low < 1e-9:
        low, high = low - 0.5, high + 0.5
    count = max((len(series) for series in curves.values()), default=1)

    def point(index: int, value: float) -> tuple[int, int]:
        x = left + (width - left - right) * (index / max(count - 1, 1))
        y = top + (height - top - bottom) * (1.0 - (value - low) / (high - low))
        return int(round(x)), int(round(y))

    for tick in range(5):
        value = low + (high - low) * tick / 4
        _, y = point(0, value)
        cv2.line(image, (left, y), (width - right, y), _GREY, 1)
        _text(image, f"{value:.3g}", (5, y + 4), 0.4)
    for index in range(count):
        x, _ = point(index, low)
        _text(image, str(index + 1), (x - 4, height - bottom + 18), 0.4)
    cv2.rectangle(image, (left, top), (width - right, height - bottom), _BLACK, 1)
    for number, (name, series) in enumerate(curves.items()):
        colour = _COLOURS[number % len(_COLOURS)]
        points = [point(i, v) for i, v in enumerate(series) if np.isfinite(v)]
        for start, end in zip(points, points[1:], strict=False):
            cv2.line(image, start, end, colour, 2, cv2.LINE_AA)
        for centre in points:
            cv2.circle(image, centre, 3, colour, -1, cv2.LINE_AA)
        cv2.line(image, (left + 10 + 160 * number, 22), (left + 35 + 160 * number, 22), colour, 2)
        _text(image, name, (left + 40 + 160 * number, 26))
    _text(image, title, (left, 14), 0.5)
    _text(image, x_label, (width // 2 - 20, height - 10))
    return _write(path, image)


def plot_confusions(path: str | Path, matrices: Mapping[str, ConfusionCounts]) -> Path:
    """One 2 x 2 confusion matrix per entry (rows truth, columns prediction) with its metrics."""
    cell, margin = 110, 90
    panel_width, panel_height = margin + 2 * cell + 20, margin + 2 * cell + 90
    image = np.full((panel_height, panel_width * max(len(matrices), 1), 3), 255, dtype=np.uint8)
    for number, (name, counts) in enumerate(matrices.items()):
        x0 = number * panel_width
        grid = np.array([[counts.true_positives, counts.false_negatives],
                         [counts.false_positives, counts.true_negatives]], dtype=np.float64)
        row_totals = np.maximum(grid.sum(axis=1, keepdims=True), 1.0)
        _text(image, name, (x0 + 10, 20), 0.5)
        for column, label in enumerate(("same", "different")):
            _text(image, label, (x0 + margin + column * cell + 20, margin - 10), 0.45)
        _text(image, "prediction", (x0 + margin + cell - 40, 45), 0.4)
        for row, label in enumerate(("same", "different")):
            _text(image, label, (x0 + 5, margin + row * cell + cell // 2), 0.45)
            for column in range(2):
                share = grid[row, column] / row_totals[row, 0]
                shade = int(255 - 170 * share)
                top_left = (x0 + margin + column * cell, margin + row * cell)
                bottom_right = (top_left[0] + cell - 2, top_left[1] + cell - 2)
                cv2.rectangle(image, top_left, bottom_right, (255, shade, shade), -1)
                cv2.rectangle(image, top_left, bottom_right, _BLACK, 1)
                colour = _WHITE if share > 0.6 else _BLACK
                _text(image, f"{int(grid[row, column])}", (top_left[0] + 10, top_left[1] + 50), 0.55, colour)
                _text(image, f"{100 * share:.1f}%", (top_left[0] + 10, top_left[1] + 75), 0.45, colour)
        summary = (f"acc {counts.accuracy:.4f}  prec {counts.precision:.4f}",
                   f"rec {counts.recall:.4f}  F1 {counts.f1:.4f}")
        for line, text in enumerate(summary):
            _text(image, text, (x0 + 10, margin + 2 * cell + 30 + 22 * line), 0.45)
    return _write(path, image)


def _write(path: str | Path, image: np.ndarray) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if not cv2.imwrite(str(path), image):
        raise OSError(f"could not write the plot {path}")
    return path


def plot_threshold_sweeps(path: str | Path, sweeps: Mapping[str, ThresholdSweep], threshold: float) -> Path:
    """F1 of each named sweep against the threshold, the anchoring layer's ``threshold`` marked and
    each curve's best point labelled: where the cut is, and where it would score the pairs best."""
    width, height, left, right, top, bottom = 720, 420, 70, 20, 40, 50
    image = np.full((height, width, 3), 255, dtype=np.uint8)
    curves = {name: sweep.f1_curve() for name, sweep in sweeps.items()}
    low = 0.5  # below, a curve only says "everything taken for the same" or "nothing": drawn at the floor

    def point(x: float, value: float) -> tuple[int, int]:
        return (int(round(left + (width - left - right) * x)),
                int(round(top + (height - top - bottom) * (1.0 - (value - low) / (1.0 - low)))))

    for tick in range(5):
        value = low + (1.0 - low) * tick / 4
        _, y = point(0.0, value)
        cv2.line(image, (left, y), (width - right, y), _GREY, 1)
        _text(image, f"{value:.3g}", (5, y + 4), 0.4)
        x, _ = point(tick / 4, low)
        _text(image, f"{tick / 4:g}", (x - 8, height - bottom + 18), 0.4)
    cv2.rectangle(image, (left, top), (width - right, height - bottom), _BLACK, 1)
    marker_x, _ = point(threshold, low)
    cv2.line(image, (marker_x, top), (marker_x, height - bottom), _BLACK, 1)
    _text(image, f"anchoring threshold {threshold:g}", (marker_x + 4, height - bottom - 6), 0.4)
    for number, (name, sweep) in enumerate(sweeps.items()):
        colour = _COLOURS[number % len(_COLOURS)]
        curve, xs = curves[name], sweep.thresholds()
        points = [point(x, max(v, low)) for x, v in zip(xs, curve, strict=True) if np.isfinite(v)]
        for start, end in zip(points, points[1:], strict=False):
            cv2.line(image, start, end, colour, 2, cv2.LINE_AA)
        best_threshold, best = sweep.best()
        label = name
        if math.isfinite(best_threshold):
            cv2.circle(image, point(best_threshold, max(best.f1, low)), 5, colour, -1, cv2.LINE_AA)
            label += f": best {best.f1:.4f} at {best_threshold:.3f}"
        legend_y = height - bottom - 30 - 18 * (len(sweeps) - 1 - number)
        cv2.line(image, (width - right - 300, legend_y - 4), (width - right - 275, legend_y - 4), colour, 2)
        _text(image, label, (width - right - 270, legend_y), 0.4)
    _text(image, "pair F1 against the threshold", (left, 14), 0.5)
    _text(image, "threshold", (width // 2 - 30, height - 10))
    return _write(path, image)
