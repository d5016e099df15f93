"""The report's PNG plots, drawn with OpenCV (matplotlib is not a dependency): curves over an x axis
(linear or logarithmic), and a latency distribution as histogram plus CDF."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import cv2
import numpy as np

from harness.results import DistributionPlot, LinePlot, format_value, percentile

WIDTH, HEIGHT = 860, 500
LEFT, RIGHT, TOP, BOTTOM = 80, 30, 60, 60
WHITE, BLACK, GREY, LIGHT = (255, 255, 255), (0, 0, 0), (150, 150, 150), (225, 225, 225)
COLOURS = ((200, 90, 30), (40, 130, 230), (60, 160, 60), (150, 60, 170), (30, 30, 200), (120, 120, 0))  # BGR
FONT = cv2.FONT_HERSHEY_SIMPLEX


def text(image: np.ndarray, content: str, origin: tuple[int, int], scale: float = 0.42, colour=BLACK) -> None:
    cv2.putText(image, content, origin, FONT, scale, colour, 1, cv2.LINE_AA)


def tick_label(value: float) -> str:
    return f"{int(value):,}" if float(value).is_integer() else f"{value:g}"


def nice_ticks(low: float, high: float, count: int = 5) -> list[float]:
    if not high > low:
        return [low]
    raw = (high - low) / count
    magnitude = 10.0 ** math.floor(math.log10(raw))
    step = next(m * magnitude for m in (1.0, 2.0, 5.0, 10.0) if m * magnitude >= raw)
    first = math.ceil(low / step) * step
    return [first + i * step for i in range(int((high - first) / step + 1e-9) + 1)]


def log_ticks(low: float, high: float) -> list[float]:
    ticks = []
    for exponent in range(math.floor(math.log10(low)), math.ceil(math.log10(high)) + 1):
        for mantissa in (1.0, 2.0, 5.0):
            value = mantissa * 10.0**exponent
            if low <= value <= high:
                ticks.append(value)
    return ticks if len(ticks) >= 2 else [low, high]


class Axes:
    """Maps data to pixels inside a panel; log axes map log10 of the value."""

    def __init__(self, box: tuple[int, int, int, int], x_range: tuple[float, float], y_range: tuple[float, float],
                 log_x: bool = False, log_y: bool = False) -> None:
        self.left, self.top, self.right, self.bottom = box
        self.log_x, self.log_y = log_x, log_y
        self.x_range = self._padded(x_range, log_x, 0.0)
        self.y_range = self._padded(y_range, log_y, 0.05)

    @staticmethod
    def _padded(bounds: tuple[float, float], logarithmic: bool, margin: float) -> tuple[float, float]:
        low, high = bounds
        if logarithmic:
            low, high = math.log10(low), math.log10(high)
        if high - low < 1e-12:
            low, high = low - 0.5, high + 0.5
        span = high - low
        return low - margin * span, high + margin * span

    def x(self, value: float) -> int:
        value = math.log10(value) if self.log_x else value
        low, high = self.x_range
        return int(round(self.left + (self.right - self.left) * (value - low) / (high - low)))

    def y(self, value: float) -> int:
        value = math.log10(value) if self.log_y else value
        low, high = self.y_range
        return int(round(self.bottom - (self.bottom - self.top) * (value - low) / (high - low)))

    def draw_frame(self, image: np.ndarray, x_ticks: Sequence[float], y_ticks: Sequence[float],
                   x_label: str, y_label: str) -> None:
        for tick in y_ticks:
            y = self.y(tick)
            if self.top <= y <= self.bottom:
                cv2.line(image, (self.left, y), (self.right, y), LIGHT, 1)
                label = tick_label(tick)
                (width, _), _ = cv2.getTextSize(label, FONT, 0.38, 1)
                text(image, label, (self.left - 6 - width, y + 4), 0.38)
        for tick in x_ticks:
            x = self.x(tick)
            if self.left <= x <= self.right:
                cv2.line(image, (x, self.top), (x, self.bottom), LIGHT, 1)
                label = tick_label(tick)
                (width, _), _ = cv2.getTextSize(label, FONT, 0.38, 1)
                text(image, label, (x - width // 2, self.bottom + 16), 0.38)
        cv2.rectangle(image, (self.left, self.top), (self.right, self.bottom), BLACK, 1)
        text(image, x_label, ((self.left + self.right) // 2 - 4 * len(x_label), self.bottom + 38))
        text(image, y_label, (self.left - 70, self.top - 10))


def _legend(image: np.ndarray, entries: Sequence[str], left: int, top: int) -> None:
    for number, entry in enumerate(entries):
        y = top + 18 * number
        colour = COLOURS[number % len(COLOURS)]
        cv2.line(image, (left, y - 4), (left + 22, y - 4), colour, 2)
        text(image, entry, (left + 28, y), 0.4)


def _polyline(image: np.ndarray, points: list[tuple[int, int]], colour: tuple[int, int, int]) -> None:
    for start, end in zip(points, points[1:], strict=False):
        cv2.line(image, start, end, colour, 2, cv2.LINE_AA)


def line_plot(path: Path, plot: LinePlot) -> Path:
    image = np.full((HEIGHT, WIDTH, 3), 255, dtype=np.uint8)
    xs = [float(x) for x in plot.x]
    values = [v for line in plot.lines.values() for v in line if v is not None and math.isfinite(v)]
    values = [v for v in values if v > 0] if plot.log_y else values
    if not xs or not values:
        text(image, f"{plot.title}: nothing measured", (LEFT, TOP))
        return _write(path, image)
    top = TOP + 18 * len(plot.lines)  # below the legend
    axes = Axes((LEFT, top, WIDTH - RIGHT, HEIGHT - BOTTOM), (min(xs), max(xs)), (min(values), max(values)),
                plot.log_x, plot.log_y)
    x_ticks = log_ticks(min(xs), max(xs)) if plot.log_x else nice_ticks(min(xs), max(xs))
    low, high = min(values), max(values)
    y_ticks = log_ticks(low, high) if plot.log_y else nice_ticks(low, high)
    axes.draw_frame(image, x_ticks, y_ticks, plot.x_label + (" (log)" if plot.log_x else ""),
                    plot.y_label + (" (log)" if plot.log_y else ""))
    for label, position in plot.vertical_lines.items():
        x = axes.x(position)
        for y in range(top, HEIGHT - BOTTOM, 8):
            cv2.line(image, (x, y), (x, min(y + 4, HEIGHT - BOTTOM)), GREY, 1)
        text(image, label, (x + 4, top + 14), 0.38, GREY)
    for number, line in enumerate(plot.lines.values()):
        colour = COLOURS[number % len(COLOURS)]
        segment: list[tuple[int, int]] = []
        for x, value in zip(xs, line, strict=False):
            if value is None or not math.isfinite(value) or (plot.log_y and value <= 0):
                _polyline(image, segment, colour)
                segment = []
                continue
            segment.append((axes.x(x), axes.y(value)))
        _polyline(image, segment, colour)
        if len(xs) <= 30:
            for x, value in zip(xs, line, strict=False):
                if value is not None and math.isfinite(value) and not (plot.log_y and value <= 0):
                    cv2.circle(image, (axes.x(x), axes.y(value)), 3, colour, -1, cv2.LINE_AA)
    text(image, plot.title, (LEFT, 22), 0.52)
    _legend(image, list(plot.lines), LEFT + 10, 42)
    return _write(path, image)


def distribution_plot(path: Path, plot: DistributionPlot) -> Path:
    """Histogram (left) and cumulative distribution (right) of each condition's samples."""
    image = np.full((HEIGHT, WIDTH, 3), 255, dtype=np.uint8)
    series = {name: np.asarray(values, dtype=np.float64) for name, values in plot.samples.items() if len(values)}
    text(image, plot.title, (LEFT, 22), 0.52)
    if not series:
        text(image, "no samples", (LEFT, TOP + 20))
        return _write(path, image)
    everything = np.concatenate(list(series.values()))
    low, high = 0.0, float(everything.max()) * 1.02 or 1.0
    edges = np.linspace(low, high, 41)
    counts = {name: np.histogram(values, edges)[0] / len(values) for name, values in series.items()}
    panel_width = (WIDTH - LEFT - RIGHT - 70) // 2
    top = TOP + 18 * len(series)  # below the legend
    histogram = Axes((LEFT, top, LEFT + panel_width, HEIGHT - BOTTOM), (low, high),
                     (0.0, max(float(c.max()) for c in counts.values())))
    cdf = Axes((LEFT + panel_width + 70, top, WIDTH - RIGHT, HEIGHT - BOTTOM), (low, high), (0.0, 1.0))
    histogram.draw_frame(image, nice_ticks(low, high), nice_ticks(0.0, max(float(c.max()) for c in counts.values())),
                         plot.unit, "fraction of frames")
    cdf.draw_frame(image, nice_ticks(low, high), [0.0, 0.25, 0.5, 0.75, 0.95, 1.0], plot.unit, "cumulative")
    for number, (name, values) in enumerate(series.items()):
        colour = COLOURS[number % len(COLOURS)]
        steps = []
        for left, right, share in zip(edges[:-1], edges[1:], counts[name], strict=True):
            steps += [(histogram.x(left), histogram.y(share)), (histogram.x(right), histogram.y(share))]
        _polyline(image, steps, colour)
        ordered = np.sort(values)
        fractions = np.arange(1, len(ordered) + 1) / len(ordered)
        _polyline(image, [(cdf.x(v), cdf.y(f)) for v, f in _thin(ordered, fractions)], colour)
    entries = [f"{name}: p50 {format_value(percentile(list(v), 0.5))}, p95 {format_value(percentile(list(v), 0.95))},"
               f" max {format_value(float(v.max()))} {plot.unit} (n={len(v)})" for name, v in series.items()]
    _legend(image, entries, LEFT + 10, 44)
    return _write(path, image)


def _thin(values: np.ndarray, fractions: np.ndarray, limit: int = 2000) -> list[tuple[float, float]]:
    step = max(len(values) // limit, 1)
    indices = list(range(0, len(values), step))
    if indices[-1] != len(values) - 1:
        indices.append(len(values) - 1)
    return [(float(values[i]), float(fractions[i])) for i in indices]


def _write(path: Path, image: np.ndarray) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    if not cv2.imwrite(str(path), image):
        raise OSError(f"could not write the plot {path}")
    return path

