"""``sailor train`` and ``sailor evaluate`` end to end, on a few generated scenes."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

pytest.importorskip("torch", reason="pip install torch==2.13.0 (CPU build)")

from merlin2_sailor.cli.main import build_parser, main  # noqa: E402
from merlin2_sailor.training.photo_library import DARKNET_ENVIRONMENT_VARIABLE, DEFAULT_DARKNET_FOLDER  # noqa: E402

darknet = Path(os.environ.get(DARKNET_ENVIRONMENT_VARIABLE) or DEFAULT_DARKNET_FOLDER)
needs_darknet = pytest.mark.skipif(not (darknet / "dog.jpg").is_file(), reason="run scripts/fetch_test_data.sh")


def test_both_subcommands_are_registered() -> None:
    arguments = build_parser().parse_args(["train", "--epochs", "2"])
    assert arguments.epochs == 2 and arguments.learning_rate == 0.001
    assert arguments.source == "houses"  # the default weights' source
    assert build_parser().parse_args(["evaluate"]).split == "test"


@needs_darknet
def test_train_then_evaluate_a_few_scenes(tmp_path, capsys) -> None:
    weights = tmp_path / "net.pt"
    cache = ["--cache", str(tmp_path / "cache")]
    assert main(["train", "--source", "generated", "--train-scenes", "2", "--validation-scenes", "1", "--epochs", "2",
                 "--output", str(weights), "--device", "cpu", *cache]) == 0
    assert weights.is_file() and (tmp_path / "net_loss.png").is_file()
    assert json.loads(weights.with_suffix(".json").read_text())["splits"] == {"train": 2, "validation": 1, "test": 0}
    assert main(["evaluate", "--source", "generated", "--weights", str(weights), "--scenes", "1",
                 "--output", str(tmp_path / "eval"), "--set", "match_threshold=0.6", *cache]) == 0
    output = capsys.readouterr().out
    assert "network look-alike" in output and "IDF1" in output
    report = json.loads((tmp_path / "eval" / "metrics.json").read_text())
    # The anchoring node's settings, with the command line's: both matchers are judged at them.
    assert "threshold 0.6" in output and report["anchoring_settings"]["match_threshold"] == 0.6
    assert report["anchoring_settings"]["weights"] == str(weights)
    # Replaced pairs copy revisits (an object seen again 20 s or more later), which a single
    # generated scene may not hold; when there are some, both matchers are scored on them.
    replaced = {"network replaced", "rules replaced"}
    assert set(report["pairs"]) - replaced == {"network", "rules", "network look-alike", "rules look-alike",
                                               "network partial view", "rules partial view", "network searched",
                                               "rules searched", "network as run"}
    assert len(set(report["pairs"]) & replaced) in (0, 2)
    assert (tmp_path / "eval" / "confusion.png").is_file()
    # The same pairs at every threshold: at the anchoring threshold, the very counts of the table.
    sweeps = report["threshold_sweep"]
    assert set(sweeps) == {"network", "rules", "network as run"}
    for name in ("network", "rules"):
        counts = ("true_positives", "false_positives", "false_negatives", "true_negatives")
        assert [sweeps[name]["at_threshold"][key] for key in counts] == [report["pairs"][name][key] for key in counts]
        assert sweeps[name]["best"]["f1"] >= report["pairs"][name]["f1"]
    assert "every pair of Algorithm 3 again, at every threshold" in output
    assert (tmp_path / "eval" / "threshold_sweep.png").is_file()


def test_a_weights_file_that_does_not_exist_is_one_clear_error(tmp_path, capsys) -> None:
    assert main(["evaluate", "--weights", str(tmp_path / "missing.pt")]) == 2
    assert "not found" in capsys.readouterr().err


@needs_darknet
def test_train_and_evaluate_on_generated_houses(tmp_path, capsys) -> None:
    weights = tmp_path / "net.pt"
    cache = ["--cache", str(tmp_path / "cache")]
    assert main(["train", "--source", "houses", "--train-scenes", "1", "--validation-scenes", "1", "--epochs", "1",
                 "--output", str(weights), "--device", "cpu", *cache]) == 0
    provenance = json.loads(weights.with_suffix(".json").read_text())
    assert provenance["source"] == "houses" and provenance["training"]["positive_weight"] == 8.0
    assert list((tmp_path / "cache" / "houses").glob("*/train-0.json"))  # the tour is rendered once
    assert main(["evaluate", "--source", "houses", "--weights", str(weights), "--scenes", "1", "--no-identity",
                 *cache]) == 0
    output = capsys.readouterr().out
    assert "network partial view" in output and "rules partial view" in output


def test_evaluate_tours_a_world_with_both_matchers(tmp_path, capsys) -> None:
    import yaml

    # one room, three mugs on the floor in front of the robot's only waypoint
    room = {
        "house": {"rooms": [{"name": "room", "x_min": 0.0, "y_min": 0.0, "x_max": 5.0, "y_max": 4.0}],
                  "waypoints": [{"name": "start", "x": 1.0, "y": 2.0, "yaw": 0.0}]},
        "textures": {"mug": {"photo": "skimage/coffee", "crop": [173, 13, 411, 239]}},
        "objects": [{"id": f"mug_{k}", "class": "cup", "position": [3.0, 1.4 + 0.6 * k], "size": [0.1, 0.1, 0.11],
                     "texture": "mug"} for k in range(3)],
        "robot": {"start": "start"},
    }
    world = tmp_path / "room.yaml"
    world.write_text(yaml.safe_dump(room))
    assert main(["evaluate", "--world", str(world), "--world-seeds", "0", "--output", str(tmp_path / "tour")]) == 0
    output = capsys.readouterr().out
    assert "duplicates" in output and "network" in output and "rules" in output
    report = json.loads((tmp_path / "tour" / "tour.json").read_text())
    assert {run["matcher"] for run in report["runs"]} == {"network", "rules"}
    assert all(run["scorecard"]["objects"] == 3 for run in report["runs"])
