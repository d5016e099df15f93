"""``sailor demo``: its output folder is emptied of a previous run's files, never of anyone else's."""

from __future__ import annotations

import pytest

from merlin2_sailor.cli.demo_command import prepare_output
from merlin2_sailor.cli.main import build_parser
from merlin2_sailor.errors import ConfigurationError


def test_a_new_folder_is_made_and_returned_absolute(tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    folder = prepare_output(tmp_path.relative_to(tmp_path) / "reports" / "demo")
    assert folder.is_absolute() and folder.is_dir() and folder == tmp_path / "reports" / "demo"


def test_a_previous_runs_files_are_removed_so_the_robot_starts_knowing_nothing(tmp_path) -> None:
    (tmp_path / "report" / "frames").mkdir(parents=True)
    (tmp_path / "report" / "summary.md").write_text("old")
    (tmp_path / "anchoring").mkdir()
    (tmp_path / "knowledge.db").write_bytes(b"old")
    (tmp_path / "ground_truth.json").write_text("{}")
    assert prepare_output(tmp_path) == tmp_path.resolve()
    assert list(tmp_path.iterdir()) == []


def test_a_folder_with_other_files_is_refused_and_left_alone(tmp_path) -> None:
    (tmp_path / "thesis.tex").write_text("precious")
    (tmp_path / "knowledge.db").write_bytes(b"old")
    with pytest.raises(ConfigurationError, match="thesis.tex"):
        prepare_output(tmp_path)
    assert (tmp_path / "thesis.tex").read_text() == "precious" and (tmp_path / "knowledge.db").exists()


def test_a_file_is_not_an_output_folder(tmp_path) -> None:
    (tmp_path / "out").write_text("")
    with pytest.raises(ConfigurationError, match="not a folder"):
        prepare_output(tmp_path / "out")


def test_the_command_is_registered_with_its_options() -> None:
    arguments = build_parser().parse_args(["demo", "--output", "somewhere", "--grace-period", "5"])
    assert str(arguments.output) == "somewhere" and arguments.grace_period == 5.0
