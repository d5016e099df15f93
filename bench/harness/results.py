"""The structured result of one benchmark: figures (each with its baseline), tables and plot data.

A benchmark's ``run()`` returns a :class:`BenchmarkResult`; its script prints it, ``sailor bench``
collects it as JSON (``to_dict`` / ``from_dict``) and renders it into report.md and PNG plots.
Every figure is measured in the same run as its baseline, so their ratio is not skewed by a
machine that was busier at another time.
"""

from __future__ import annotations

import math
import statistics
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any, Literal

Better = Literal["lower", "higher"]


@dataclass
class Figure:
    """One measured number; ``baseline`` is what it is compared with, measured in the same run.

    ``better`` says which direction is good, so that :attr:`ratio` is always "how many times
    better ours is": baseline / value for a cost, value / baseline for a rate.
    """

    name: str
    value: float
    unit: str
    baseline: float | None = None
    baseline_name: str = ""
    better: Better = "lower"
    target: str = ""
    met: bool | None = None  # whether ``target`` is met; None when there is no target

    @property
    def ratio(self) -> float | None:
        if self.baseline is None or not (math.isfinite(self.value) and math.isfinite(self.baseline)):
            return None
        numerator, denominator = (self.baseline, self.value) if self.better == "lower" else (self.value, self.baseline)
        return numerator / denominator if denominator > 0.0 else None


@dataclass
class Table:
    """A table of detail rows (sizes of a sweep, per-node figures) for the report."""

    title: str
    columns: list[str]
    rows: list[list[Any]]


@dataclass
class LinePlot:
    """Curves over a shared x axis: ``lines`` maps a curve's name to its y values (None: not measured)."""

    key: str  # file name stem of the PNG
    title: str
    x_label: str
    y_label: str
    x: list[float]
    lines: dict[str, list[float | None]]
    log_x: bool = False
    log_y: bool = False
    vertical_lines: dict[str, float] = field(default_factory=dict)  # labelled x positions (phase starts)


@dataclass
class DistributionPlot:
    """Samples of one quantity under several conditions: drawn as a histogram and a CDF."""

    key: str
    title: str
    unit: str
    samples: dict[str, list[float]]


@dataclass
class BenchmarkResult:
    name: str
    title: str
    description: str
    parameters: dict[str, Any] = field(default_factory=dict)
    figures: list[Figure] = field(default_factory=list)
    tables: list[Table] = field(default_factory=list)
    line_plots: list[LinePlot] = field(default_factory=list)
    distributions: list[DistributionPlot] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    extra: dict[str, Any] = field(default_factory=dict)  # raw data kept in results.json only

    def figure(self, name: str, value: float, unit: str, **details: Any) -> Figure:
        figure = Figure(name, float(value), unit, **details)
        self.figures.append(figure)
        return figure

    def to_dict(self) -> dict[str, Any]:
        data = asdict(self)
        for figure, record in zip(self.figures, data["figures"], strict=True):
            record["ratio"] = figure.ratio
        return data

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> BenchmarkResult:
        figure_fields = set(Figure.__dataclass_fields__)
        return cls(
            name=data["name"], title=data["title"], description=data["description"],
            parameters=dict(data.get("parameters", {})),
            figures=[Figure(**{k: v for k, v in f.items() if k in figure_fields}) for f in data.get("figures", [])],
            tables=[Table(**t) for t in data.get("tables", [])],
            line_plots=[LinePlot(**p) for p in data.get("line_plots", [])],
            distributions=[DistributionPlot(**d) for d in data.get("distributions", [])],
            notes=list(data.get("notes", [])),
            extra=dict(data.get("extra", {})),
        )

    def text(self) -> str:
        """The figures as aligned console lines."""
        width = max((len(f.name) for f in self.figures), default=10)
        lines = [f"{self.title}"]
        for figure in self.figures:
            line = f"  {figure.name:<{width}}  {format_value(figure.value)} {figure.unit}"
            if figure.baseline is not None:
                ratio = figure.ratio
                line += f"  | {figure.baseline_name}: {format_value(figure.baseline)} {figure.unit}"
                line += f"  ({format_value(ratio)}x)" if ratio is not None else ""
            if figure.target:
                verdict = {True: "met", False: "NOT met", None: "-"}[figure.met]
                line += f"  | target {figure.target}: {verdict}"
            lines.append(line)
        for table in self.tables:
            lines.append(f"  {table.title}:")
            cells = [[str(c) for c in table.columns]] + [[_cell(v) for v in row] for row in table.rows]
            widths = [max(len(row[i]) for row in cells) for i in range(len(table.columns))]
            lines.extend("    " + "  ".join(c.rjust(w) for c, w in zip(row, widths, strict=True)) for row in cells)
        lines.extend(f"  note: {note}" for note in self.notes)
        return "\n".join(lines)


def json_safe(value: Any) -> Any:
    """``value`` with every non-finite float replaced by None (JSON has no NaN) and NumPy scalars as Python's."""
    if isinstance(value, Mapping):
        return {str(key): json_safe(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_safe(item) for item in value]
    if hasattr(value, "item") and not isinstance(value, (str, bytes)):  # a NumPy scalar
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def format_value(value: float | None) -> str:
    """Three significant digits, without scientific notation for everyday magnitudes."""
    if value is None or not math.isfinite(value):
        return "-" if value is None else str(value)
    if float(value).is_integer() and abs(value) < 1e15:  # counts, and figures that happen to be whole
        return f"{int(value):,}"
    magnitude = abs(value)
    if magnitude >= 1000.0:
        return f"{value:,.0f}"
    if magnitude >= 100.0:
        return f"{value:.0f}"
    if magnitude >= 10.0:
        return f"{value:.1f}"
    if magnitude >= 1.0:
        return f"{value:.2f}"
    if magnitude >= 0.01:
        return f"{value:.3f}"
    return f"{value:.2e}"


def _cell(value: Any) -> str:
    return format_value(value) if isinstance(value, float) or value is None else str(value)


def median_seconds(function: Callable[[], object], repeats: int, warm_up: int = 1) -> float:
    """Median seconds per call: another process on a shared machine skews a median little."""
    for _ in range(warm_up):
        function()
    times = []
    for _ in range(max(repeats, 1)):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def percentile(samples: Sequence[float], fraction: float) -> float:
    """The ``fraction`` quantile (0..1) by linear interpolation; NaN for no samples."""
    if not samples:
        return math.nan
    ordered = sorted(samples)
    position = fraction * (len(ordered) - 1)
    low = math.floor(position)
    high = min(low + 1, len(ordered) - 1)
    return ordered[low] + (ordered[high] - ordered[low]) * (position - low)
