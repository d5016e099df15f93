"""The report folder of ``sailor bench``: report.md, results.json and the PNG plots.

report.md opens with the machine (CPU model, cores, RAM, Python, OS, load average) and a summary,
then one section per benchmark: what was measured, a table of its figures each beside its baseline
measured in the same run and their ratio, its detail tables and plots.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from harness.machine import summary
from harness.plots import distribution_plot, line_plot
from harness.results import BenchmarkResult, Figure, format_value, json_safe

PLOTS_FOLDER = "plots"


@dataclass
class BenchmarkRun:
    """One benchmark's outcome within ``sailor bench``."""

    name: str
    seconds: float
    result: BenchmarkResult | None = None
    error: str = ""  # why it failed; empty when it ran
    plots: list[str] = field(default_factory=list)  # relative to the report folder

    @property
    def succeeded(self) -> bool:
        return self.result is not None and not self.error


def _cell(value: Any) -> str:
    if isinstance(value, float) or value is None:
        value = format_value(value)
    return str(value).replace("|", "\\|").replace("\n", " ")


def markdown_table(columns: Sequence[str], rows: Sequence[Sequence[Any]], align_right_from: int = 1) -> str:
    header = "| " + " | ".join(_cell(c) for c in columns) + " |"
    rule = "| " + " | ".join("---:" if i >= align_right_from else "---" for i in range(len(columns))) + " |"
    body = ["| " + " | ".join(_cell(v) for v in row) + " |" for row in rows]
    return "\n".join([header, rule, *body])


def _ratio(figure: Figure) -> str:
    ratio = figure.ratio
    return "" if ratio is None else f"{format_value(ratio)}×"


def _target(figure: Figure) -> str:
    if not figure.target:
        return ""
    verdict = {True: "met", False: "**NOT met**", None: ""}[figure.met]
    return f"{figure.target}: {verdict}"


def figures_table(result: BenchmarkResult) -> str:
    rows = [[figure.name, f"{format_value(figure.value)} {figure.unit}",
             f"{figure.baseline_name}: {format_value(figure.baseline)} {figure.unit}" if figure.baseline is not None
             else "", _ratio(figure), _target(figure)] for figure in result.figures]
    return markdown_table(["figure", "ours", "baseline (same run)", "ratio", "target"], rows, align_right_from=99)


def draw_plots(folder: Path, result: BenchmarkResult) -> list[str]:
    written = []
    for plot in result.line_plots:
        written.append(line_plot(folder / PLOTS_FOLDER / f"{plot.key}.png", plot))
    for distribution in result.distributions:
        written.append(distribution_plot(folder / PLOTS_FOLDER / f"{distribution.key}.png", distribution))
    return [str(path.relative_to(folder)) for path in written]


def _targets(result: BenchmarkResult) -> str:
    judged = [figure for figure in result.figures if figure.met is not None]
    return f"{sum(f.met for f in judged)} / {len(judged)}" if judged else "-"


def render(runs: Sequence[BenchmarkRun], machine: dict[str, Any], header: dict[str, Any]) -> str:
    load_end = header.get("load_average_end")
    load_start = machine.get("load_average")
    lines = [
        "# merlin2_sailor benchmarks", "",
        f"`{header['command']}`, started {header['started']}, {header['seconds']:.0f} s in all.", "",
        "## Machine", "",
        markdown_table(["", ""], [
            ["CPU", f"{machine['cpu']} ({machine['architecture']})"],
            ["cores", f"{machine['logical_cpus']} logical, {machine['usable_cpus']} usable by this run"],
            ["RAM", f"{machine['memory_gib']:.1f} GiB" if machine.get("memory_gib") else "unknown"],
            ["Python", f"{machine['python']}, NumPy {machine['numpy']}"],
            ["OS", machine["os"]],
            ["load average (1 min) at start / end",
             f"{load_start[0]:.2f} / {load_end[0]:.2f}" if load_start and load_end else "unknown"],
        ], align_right_from=99), "",
    ]
    if header.get("quick"):
        lines += ["> **Short form (`--quick`)**: smaller sizes and shorter runs than the full form; "
                  "its figures are for a smoke check, not for quoting.", ""]
    lines += ["> Each figure's baseline is measured in the same run, so ratios survive a busy machine better than "
              "absolute times; a load average near the core count means other work shared the CPU.", "",
              "## Summary", "",
              markdown_table(["benchmark", "status", "seconds", "targets met"], [
                  [f"[{run.name}](#{run.name})", "ok" if run.succeeded else "**failed**", f"{run.seconds:.1f}",
                   _targets(run.result) if run.result else "-"] for run in runs], align_right_from=2), ""]
    for run in runs:
        lines += [f'<a id="{run.name}"></a>', ""]
        if not run.succeeded:
            lines += [f"## {run.name}: failed", "", "```", run.error.strip()[-3000:], "```", ""]
            continue
        result = run.result
        assert result is not None
        lines += [f"## {run.name}: {result.title}", "", result.description, "", figures_table(result), ""]
        for table in result.tables:
            lines += [f"**{table.title}**", "", markdown_table(table.columns, table.rows), ""]
        for plot in run.plots:
            lines += [f"![{Path(plot).stem}]({plot})", ""]
        lines += [f"- {note}" for note in result.notes]
        lines += [""] if result.notes else []
    return "\n".join(lines)


def write_report(folder: Path, runs: Sequence[BenchmarkRun], machine: dict[str, Any],
                 header: dict[str, Any]) -> dict[str, Path]:
    """Write report.md, results.json and the plots into ``folder``; returns their paths."""
    folder.mkdir(parents=True, exist_ok=True)
    for run in runs:
        if run.result is not None:
            run.plots = draw_plots(folder, run.result)
    report = folder / "report.md"
    report.write_text(render(runs, machine, header) + "\n")
    results = folder / "results.json"
    document = {
        **header, "machine": machine, "machine_summary": summary(machine),
        "benchmarks": {run.name: {"status": "ok" if run.succeeded else "failed", "seconds": round(run.seconds, 2),
                                  "error": run.error, "plots": run.plots,
                                  "result": run.result.to_dict() if run.result else None} for run in runs},
    }
    results.write_text(json.dumps(json_safe(document), indent=1) + "\n")
    return {"report": report, "results": results}
