"""The scenario suite's table: one row per run (scenario, seed, matcher), as markdown and JSON.

A run that did not end by itself within its deadline is a ``hang``, one whose mission demo wrote
no scorecard a ``crash``; both count as wrong, since nothing they claimed can be checked.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from merlin2_sailor_demos.report.verdict import Verdict

HANG = "hang"
CRASH = "crash"


@dataclass(frozen=True)
class ScenarioRun:
    """One run of one scenario and its verdict (None when it hung or crashed: see ``ending``)."""

    scenario: str
    seed: int
    matcher: str
    verdict: Verdict | None
    ending: str = ""
    """Empty for a run that ended by itself, else HANG or CRASH (with ``note`` saying more)."""
    wall_seconds: float = 0.0
    folder: str = ""
    note: str = ""

    @property
    def right(self) -> bool:
        return self.verdict is not None and self.verdict.right and not self.ending

    @property
    def outcome(self) -> str:
        return self.ending or (self.verdict.outcome if self.verdict else CRASH)

    def as_dict(self) -> dict[str, Any]:
        return {"scenario": self.scenario, "seed": self.seed, "matcher": self.matcher, "outcome": self.outcome,
                "right": self.right, "ending": self.ending or "ended", "wall_seconds": round(self.wall_seconds, 1),
                "folder": self.folder, "note": self.note,
                "verdict": None if self.verdict is None else self.verdict.as_dict()}

    def progress_line(self, index: int, total: int) -> str:
        """The one line printed when the run ends."""
        why = self.note if self.verdict is None else "; ".join(self.verdict.problems)
        duplicates = () if self.verdict is None else self.verdict.duplicate_origins
        return (f"[{index}/{total}] {self.scenario} seed {self.seed} {self.matcher}: "
                f"{'RIGHT' if self.right else 'WRONG'} ({self.outcome}) in {self.wall_seconds:.0f} s"
                + (f": {why}" if why else "")
                + (f" [duplicate {'; '.join(duplicates)}]" if duplicates else ""))


COLUMNS = ("scenario", "seed", "matcher", "outcome", "right/wrong", "duplicates", "undecided", "identity switches",
           "time (s)", "why wrong")


def _cells(run: ScenarioRun) -> tuple[str, ...]:
    verdict = run.verdict
    figures = ("-", "-", "-", f"{run.wall_seconds:.0f}") if verdict is None else (
        str(verdict.duplicates), str(verdict.undecided), str(verdict.identity_switches), f"{verdict.seconds:.0f}")
    why = run.note if verdict is None else "; ".join(verdict.problems)
    return (run.scenario, str(run.seed), run.matcher, run.outcome, "right" if run.right else "WRONG", *figures,
            why.replace("|", "/"))


def to_markdown(runs: Sequence[ScenarioRun]) -> str:
    """The table as markdown, with a last line counting the right runs."""
    lines = ["| " + " | ".join(COLUMNS) + " |", "|" + " --- |" * len(COLUMNS)]
    lines += ["| " + " | ".join(_cells(run)) + " |" for run in runs]
    right = sum(run.right for run in runs)
    lines += ["", f"{right} of {len(runs)} runs right; "
              f"{sum(run.verdict.duplicates for run in runs if run.verdict)} duplicate anchor(s), "
              f"{sum(run.verdict.undecided for run in runs if run.verdict)} left undecided, "
              f"{sum(run.verdict.identity_switches for run in runs if run.verdict)} identity switch(es) in all."]
    origins = [(run, origin) for run in runs if run.verdict for origin in run.verdict.duplicate_origins]
    if origins:
        lines += ["", "Duplicate anchors, and why the anchoring node made each one (its acquired event):", ""]
        lines += [f"- {run.scenario} seed {run.seed} {run.matcher}: {origin}" for run, origin in origins]
    return "\n".join(lines) + "\n"


def to_text(runs: Sequence[ScenarioRun]) -> str:
    """The table for a terminal: aligned columns, the reasons last."""
    rows = [COLUMNS, *(_cells(run) for run in runs)]
    widths = [max(len(row[i]) for row in rows) for i in range(len(COLUMNS) - 1)]
    lines = ["  ".join(cell.ljust(width) for cell, width in zip(row[:-1], widths, strict=True)).rstrip()
             + (f"  {row[-1]}" if row[-1] else "") for row in rows]
    return "\n".join(lines) + "\n"


def write_table(folder: Path, runs: Sequence[ScenarioRun]) -> tuple[Path, Path]:
    """Write ``scenarios.md`` and ``scenarios.json`` into ``folder``; return both paths."""
    folder.mkdir(parents=True, exist_ok=True)
    markdown, data = folder / "scenarios.md", folder / "scenarios.json"
    markdown.write_text("# Scenario suite\n\n" + to_markdown(runs), encoding="utf-8")
    data.write_text(json.dumps({"runs": [run.as_dict() for run in runs],
                                "right": sum(run.right for run in runs), "total": len(runs)}, indent=2),
                    encoding="utf-8")
    return markdown, data
