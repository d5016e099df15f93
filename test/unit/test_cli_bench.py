"""``sailor bench``: one fast benchmark end to end into a report folder, and the report's parts."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import cv2
import pytest

from merlin2_sailor.cli.bench import BENCHMARKS, bench_directory
from merlin2_sailor.cli.main import main

REPOSITORY_ROOT = Path(__file__).resolve().parents[2]


def figures_of(document: dict) -> list[dict]:
    return [figure for run in document["benchmarks"].values() for figure in run["result"]["figures"]]


def test_quick_run_of_one_benchmark_writes_report_json_and_plots(tmp_path, capsys) -> None:
    output = tmp_path / "report"
    assert main(["bench", "--quick", "--only", "assignment", "--output", str(output)]) == 0
    console = capsys.readouterr().out
    assert "[1/1] assignment" in console and "done in" in console and "wrote" in console

    document = json.loads((output / "results.json").read_text())
    assert document["quick"] is True and document["selected"] == ["assignment"]
    assert document["machine"]["cpu"] and document["machine"]["logical_cpus"] >= 1
    run = document["benchmarks"]["assignment"]
    assert run["status"] == "ok" and run["seconds"] > 0
    figures = figures_of(document)
    assert figures and all(isinstance(f["value"], float) and math.isfinite(f["value"]) for f in figures)
    assert any(f["baseline"] is not None and math.isfinite(f["ratio"]) for f in figures)

    report = (output / "report.md").read_text()
    assert report.startswith("# merlin2_sailor benchmarks")
    for heading in ("## Machine", "| CPU |", "| RAM |", "| Python |", "| OS |", "## assignment:",
                    "| figure | ours | baseline (same run) | ratio | target |"):
        assert heading in report, heading
    assert run["plots"] == ["plots/assignment.png"]
    image = cv2.imread(str(output / run["plots"][0]))
    assert image is not None and image.shape[0] > 100 and image.shape[1] > 100
    assert "](plots/assignment.png)" in report


def test_an_unknown_benchmark_is_refused(capsys) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["bench", "--only", "nonsense"])
    assert exit_info.value.code == 2
    assert "invalid choice" in capsys.readouterr().err


def test_every_listed_benchmark_is_a_script_of_bench() -> None:
    folder = bench_directory()
    assert folder.resolve() == (REPOSITORY_ROOT / "bench").resolve()
    for script, _ in BENCHMARKS.values():
        assert (folder / script).is_file(), script


def test_a_failing_benchmark_is_reported_and_the_others_still_run(tmp_path, monkeypatch, capsys) -> None:
    import merlin2_sailor.cli.bench as bench

    broken = tmp_path / "bench_broken.py"
    broken.write_text("raise SystemExit('this benchmark is broken')\n")
    real_command = bench.benchmark_command

    def command(folder, name, arguments, json_file, output):
        if name == "knowledge_sync":
            return [sys.executable, str(broken)]
        return real_command(folder, name, arguments, json_file, output)

    monkeypatch.setattr(bench, "benchmark_command", command)
    output = tmp_path / "report"
    assert main(["bench", "--quick", "--only", "knowledge_sync", "assignment", "--output", str(output)]) == 1
    document = json.loads((output / "results.json").read_text())
    assert document["benchmarks"]["knowledge_sync"]["status"] == "failed"
    assert "this benchmark is broken" in document["benchmarks"]["knowledge_sync"]["error"]
    assert document["benchmarks"]["assignment"]["status"] == "ok"
    report = (output / "report.md").read_text()
    assert "## knowledge_sync: failed" in report and "this benchmark is broken" in report
    assert "FAILED: knowledge_sync" in capsys.readouterr().out
