"""``--record``: any launch gets a bag recorder, and a bag is never written over."""

from __future__ import annotations

import pytest

from merlin2_sailor.cli.main import main
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.launcher import load_launch_file
from merlin2_sailor.launcher.recording import RECORDER_EXECUTABLE, with_recorder
from merlin2_sailor.launcher.spec import ExitPolicy
from merlin2_sailor.resources import find_launch_file


def test_the_recorder_joins_the_launch_as_an_observer_writing_the_named_folder(tmp_path) -> None:
    spec = load_launch_file(find_launch_file("house"))
    recorded = with_recorder(spec, tmp_path / "bag", "sqlite3")
    assert recorded.nodes[:-1] == spec.nodes
    recorder = recorded.nodes[-1]
    assert recorder.executable == RECORDER_EXECUTABLE and recorder.on_exit is ExitPolicy.IGNORE
    assert recorder.parameters[-1] == {"path": str(tmp_path / "bag"), "storage": "sqlite3"}


def test_an_existing_folder_is_refused_before_anything_starts(tmp_path, capsys) -> None:
    (tmp_path / "bag").mkdir()
    with pytest.raises(ConfigurationError, match="exists already"):
        with_recorder(load_launch_file(find_launch_file("house")), tmp_path / "bag")
    assert main(["launch", "house", "--record", str(tmp_path / "bag")]) == 2
    error = capsys.readouterr().err
    assert "exists already" in error and "Traceback" not in error
    assert main(["demo", "--all-scenarios", "--record", str(tmp_path / "other")]) == 2
    assert "--record records the default demo" in capsys.readouterr().err
