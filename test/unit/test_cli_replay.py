"""``sailor replay``: a real replay of the motorcycle, and one clear line for every bad request."""

from __future__ import annotations

import json

import pytest

from merlin2_sailor.cli.main import main
from merlin2_sailor_demos.replay.debian_data import DebianData


def error_line(capsys: pytest.CaptureFixture[str], arguments: list[str]) -> str:
    assert main(["replay", *arguments]) == 2
    error = capsys.readouterr().err.strip()
    assert len(error.splitlines()) == 1 and "Traceback" not in error
    return error


def test_the_motorcycle_replay_anchors_the_motorcycle_once_where_it_stands(tmp_path, capsys) -> None:
    pytest.importorskip("skimage.data", reason="the motorcycle source needs scikit-image (pip install scikit-image)")
    output = tmp_path / "motorcycle"
    assert main(["replay", "motorcycle", "--frames", "3", "--output", str(output)]) == 0
    printed = capsys.readouterr().out
    assert "acquired motorcycle_1" in printed and "confirmed motorcycle_1" in printed
    assert "3 frames in" in printed and "anchors 1 (1 confirmed)" in printed
    saved = json.loads((output / "anchors.json").read_text())
    (motorcycle,) = saved["anchors"]
    assert (motorcycle["symbol"], motorcycle["times_seen"], motorcycle["state"]) == ("motorcycle_1", 3, "confirmed")
    # The camera slid 5 cm sideways between the frames; the anchor stayed put in the world.
    assert motorcycle["moved_m"] < 0.05
    assert 2.0 < motorcycle["position_m"][0] < 3.0
    assert sorted(path.name for path in (output / "frames").iterdir()) == [
        "frame_000000.png", "frame_000001.png", "frame_000002.png"]
    assert (output / "anchors.md").is_file()


def test_the_replay_runs_the_anchoring_node_of_a_launch_file_offline(tmp_path, capsys) -> None:
    pytest.importorskip("skimage.data", reason="the motorcycle source needs scikit-image (pip install scikit-image)")
    output = tmp_path / "motorcycle"
    assert main(["replay", "motorcycle", "--frames", "1", "--no-video", "--output", str(output),
                 "--launch", "house", "--set", "forget_after=5.0", "--set", "confirm_after=1"]) == 0
    assert "confirmed motorcycle_1" in capsys.readouterr().out  # one sighting was enough
    anchoring = json.loads((output / "anchors.json").read_text())["anchoring"]
    # What `sailor launch house` gives the node (config/anchoring.yaml, then the house's values),
    # then the command line's; never the robot's knowledge base or state folder.
    assert (anchoring["rules_maximum_sigma"], anchoring["visible_range"]) == (0.3, 4.5)
    assert (anchoring["forget_after"], anchoring["confirm_after"]) == (5.0, 1)
    assert (anchoring["knowledge_base"], anchoring["state_folder"]) == ("", "")


def test_bad_requests_are_one_line_each(tmp_path, capsys) -> None:
    assert "unknown replay source 'kitchen'; choose one of motorcycle, sr300, vtest" in error_line(
        capsys, ["kitchen"])
    assert "no option camera_pitch" in error_line(capsys, ["motorcycle", "--camera-pitch", "30"])
    assert "--stride must be at least 1" in error_line(
        capsys, ["motorcycle", "--stride", "0", "--output", str(tmp_path)])
    assert "--every must be at least 1" in error_line(capsys, ["motorcycle", "--every", "0"])
    assert "unknown detector 'resnet'" in error_line(capsys, ["motorcycle", "--detector", "resnet"])
    assert "is not a file" in error_line(capsys, ["vtest", "--data", str(tmp_path / "missing.avi")])
    assert "no launch file 'nowhere'" in error_line(capsys, ["motorcycle", "--launch", "nowhere"])
    assert "--params robot.yaml: no such parameter file" in error_line(capsys, ["motorcycle", "--params", "robot.yaml"])
    assert "--set 'visible_range': write NAME=VALUE" in error_line(capsys, ["motorcycle", "--set", "visible_range"])
    assert "must be one of network, rules, got 'neural'" in error_line(capsys, ["motorcycle", "--matcher", "neural"])
    assert "did you mean 'visible_range'" in error_line(capsys, ["motorcycle", "--set", "visible_rnage=4.0"])
    assert "(write 5.0)" in error_line(capsys, ["motorcycle", "--set", "forget_after=5"])


def test_missing_data_says_what_to_install_instead_of_a_traceback(tmp_path, capsys, monkeypatch) -> None:
    from merlin2_sailor_demos.replay import debian_data

    monkeypatch.setattr(DebianData, "installed_path", property(lambda self: tmp_path / "not-installed"))
    monkeypatch.setenv("SAILOR_DATA_CACHE", str(tmp_path / "empty-cache"))
    monkeypatch.setattr(debian_data.shutil, "which", lambda tool: None)
    error = error_line(capsys, ["sr300"])
    assert error.startswith("sailor replay: error: the 'sr300' replay needs Debian's visp-images-data package")
    assert "--data" in error
