"""The soak's account: many demo and scenario runs, and whether any of them hung.

A soak is judged on its endings first: a ``hang`` is a run still going at its deadline (the bug
a soak hunts), a ``crash`` one that wrote no scorecard. Of the runs that ended by themselves,
``right`` ones got every claim right against the ground truth and ``wrong`` ones did not (a wrong
identity, a duplicate, a failed mission: the scenario table says which). Beside them, what each
run's log says the deadlines and the lost-result recovery did, so a soak with zero hangs also
shows whether it was the recovery that kept it from hanging.
"""

from __future__ import annotations

import json
import statistics
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from merlin2_sailor_demos.report.scenario_table import CRASH, HANG, ScenarioRun

#: What the behaviours' clients log when they ask again for a result lost on the way.
LOST_RESULT_MARK = "was lost on the way; asked for it again"
#: What the dispatcher's client logs when a step runs past its deadline and is cancelled.
DEADLINE_MARK = "passed its deadline of"


@dataclass(frozen=True)
class SoakSummary:
    runs: int
    right: int
    wrong: int
    hangs: int
    crashes: int
    lost_results_recovered: int
    steps_past_deadline: int
    slowest: ScenarioRun | None
    median_seconds: float

    @classmethod
    def of(cls, runs: Sequence[ScenarioRun]) -> SoakSummary:
        lost = deadline = 0
        for run in runs:
            log = _read(Path(run.folder) / "launch.log") if run.folder else ""
            lost += log.count(LOST_RESULT_MARK)
            deadline += log.count(DEADLINE_MARK)
        return cls(
            runs=len(runs),
            right=sum(run.right for run in runs),
            wrong=sum(not run.right and not run.ending for run in runs),
            hangs=sum(run.ending == HANG for run in runs),
            crashes=sum(run.ending == CRASH for run in runs),
            lost_results_recovered=lost,
            steps_past_deadline=deadline,
            slowest=max(runs, key=lambda run: run.wall_seconds, default=None),
            median_seconds=statistics.median(run.wall_seconds for run in runs) if runs else 0.0,
        )

    def rows(self) -> list[tuple[str, str]]:
        slowest = "-" if self.slowest is None else (
            f"{self.slowest.wall_seconds:.0f} s ({self.slowest.scenario}, seed {self.slowest.seed})")
        return [
            ("runs", str(self.runs)),
            ("right (every claim true)", str(self.right)),
            ("wrong (ended, a claim or a figure wrong)", str(self.wrong)),
            ("hangs (still running at the deadline)", str(self.hangs)),
            ("crashes (no scorecard)", str(self.crashes)),
            ("lost results asked for again", str(self.lost_results_recovered)),
            ("steps cancelled at their deadline", str(self.steps_past_deadline)),
            ("slowest run", slowest),
            ("median run", f"{self.median_seconds:.0f} s"),
        ]

    def to_markdown(self) -> str:
        lines = ["| figure | value |", "| --- | --- |"] + [f"| {name} | {value} |" for name, value in self.rows()]
        return "\n".join(lines) + "\n"

    def to_text(self) -> str:
        width = max(len(name) for name, _ in self.rows())
        return "\n".join(f"{name:<{width}}  {value}" for name, value in self.rows()) + "\n"

    def as_dict(self) -> dict[str, Any]:
        return {"runs": self.runs, "right": self.right, "wrong": self.wrong, "hangs": self.hangs,
                "crashes": self.crashes, "lost_results_recovered": self.lost_results_recovered,
                "steps_past_deadline": self.steps_past_deadline, "median_seconds": round(self.median_seconds, 1),
                "slowest": None if self.slowest is None else self.slowest.as_dict()}


def write_soak(folder: Path, summary: SoakSummary, table_markdown: str) -> tuple[Path, Path]:
    """Write ``soak.md`` (the summary, then every run's row) and ``soak.json`` into ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    markdown, data = folder / "soak.md", folder / "soak.json"
    markdown.write_text(f"# Soak\n\n{summary.to_markdown()}\n## Runs\n\n{table_markdown}", encoding="utf-8")
    data.write_text(json.dumps(summary.as_dict(), indent=2) + "\n", encoding="utf-8")
    return markdown, data


def _read(path: Path) -> str:
    try:
        return path.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return ""
