"""``sailor bench``: one fast benchmark end to end into a report folder, and the report's parts.

The command runs the checkout's bench/suite.py in a process of its own (the package never imports
bench/), so its output is read at the file descriptors (``capfd``); the suite's own behaviour
(a failing benchmark) is tested by loading the suite as bench's scripts do, with bench/ on the path.
"""

from __future__ import annotations

import importlib.util
import json
import math
import sys
from pathlib import Path
from types import ModuleType

import cv2
import numpy as np
import pytest

from merlin2_sailor.cli.bench import bench_directory
from merlin2_sailor.cli.main import main
from merlin2_sailor.errors import ConfigurationError

REPOSITORY_ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def suite(monkeypatch: pytest.MonkeyPatch) -> ModuleType:
    """bench/suite.py as a module, imported the way a script of bench/ is run: bench/ on the path."""
    monkeypatch.syspath_prepend(str(REPOSITORY_ROOT / "bench"))
    spec = importlib.util.spec_from_file_location("sailor_bench_suite", REPOSITORY_ROOT / "bench" / "suite.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def figures_of(document: dict) -> list[dict]:
    return [figure for run in document["benchmarks"].values() for figure in run["result"]["figures"]]


def test_quick_run_of_one_benchmark_writes_report_json_and_plots(tmp_path, capfd) -> None:
    output = tmp_path / "report"
    assert main(["bench", "--quick", "--only", "assignment", "--output", str(output)]) == 0
    console = capfd.readouterr().out
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


def test_an_unknown_benchmark_is_refused(capfd) -> None:
    assert main(["bench", "--only", "nonsense"]) == 2
    assert "invalid choice: 'nonsense'" in capfd.readouterr().err


def test_help_is_the_suites_and_lists_every_benchmark(capfd, suite) -> None:
    assert main(["bench", "--help"]) == 0
    shown = capfd.readouterr().out
    assert shown.startswith("usage: sailor bench")
    assert all(name in shown for name in suite.BENCHMARKS)


def test_every_listed_benchmark_is_a_script_of_bench(suite) -> None:
    folder = bench_directory()
    assert folder.resolve() == (REPOSITORY_ROOT / "bench").resolve() == suite.BENCH_FOLDER
    for script, _ in suite.BENCHMARKS.values():
        assert (folder / script).is_file(), script


def test_without_a_checkout_the_command_says_where_the_suite_is(tmp_path, monkeypatch, capsys) -> None:
    import merlin2_sailor.cli.bench as bench

    def no_share_directory() -> Path:
        raise ConfigurationError("no share folder")

    monkeypatch.setattr(bench, "share_directory", no_share_directory)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ConfigurationError, match="source checkout"):
        bench_directory()
    assert main(["bench", "--quick"]) == 2
    assert "not installed with the package" in capsys.readouterr().err


def test_a_failing_benchmark_is_reported_and_the_others_still_run(tmp_path, monkeypatch, capsys, suite) -> None:
    broken = tmp_path / "bench_broken.py"
    broken.write_text("raise SystemExit('this benchmark is broken')\n")
    real_command = suite.benchmark_command

    def command(folder, name, arguments, json_file, output):
        if name == "knowledge_sync":
            return [sys.executable, str(broken)]
        return real_command(folder, name, arguments, json_file, output)

    monkeypatch.setattr(suite, "benchmark_command", command)
    output = tmp_path / "report"
    assert suite.main(["--quick", "--only", "knowledge_sync", "assignment", "--output", str(output)]) == 1
    document = json.loads((output / "results.json").read_text())
    assert document["benchmarks"]["knowledge_sync"]["status"] == "failed"
    assert "this benchmark is broken" in document["benchmarks"]["knowledge_sync"]["error"]
    assert document["benchmarks"]["assignment"]["status"] == "ok"
    report = (output / "report.md").read_text()
    assert "## knowledge_sync: failed" in report and "this benchmark is broken" in report
    assert "FAILED: knowledge_sync" in capsys.readouterr().out


def test_the_detector_benchmarks_find_the_photos_the_tests_use_and_refuse_in_one_line_without_them(
        suite: ModuleType, monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    from harness import scene, script

    photos = tmp_path / "darknet"
    photos.mkdir()
    cv2.imwrite(str(photos / "dog.jpg"), np.zeros((8, 8, 3), np.uint8))
    monkeypatch.setenv("SAILOR_DARKNET_DATA", str(photos))
    assert scene.photo_folder() == photos and scene.require_photos() == photos
    # Unset, a checkout's copy from scripts/fetch_test_data.sh is found when the system has none.
    monkeypatch.delenv("SAILOR_DARKNET_DATA")
    monkeypatch.setattr(scene, "CHECKOUT_PHOTOS", photos)
    assert scene.photo_folder() in (photos, Path("/usr/share/darknet/data"))
    if not Path("/usr/share/darknet/data/dog.jpg").is_file():
        assert scene.photo_folder() == photos

    monkeypatch.setenv("SAILOR_DARKNET_DATA", str(tmp_path / "nowhere"))

    def run(quick: bool) -> None:
        scene.require_photos()

    assert script.main(run, "a benchmark that needs photos", argv=["--quick"]) == 2
    error = capsys.readouterr().err
    assert error.startswith("cannot run: no darknet photos in ") and "scripts/fetch_test_data.sh" in error
    assert "Traceback" not in error
