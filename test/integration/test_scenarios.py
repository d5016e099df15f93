"""A scenario of the suite end to end, through the real command: ``sailor demo --scenario``.

``moved_while_watched`` is decided by what the camera sees frame after frame (the red mug slides
along the table in view), not by appearance, so it must come out right with either matching
function: the test takes the command's default matcher, whichever it is, and checks the outcome
from the JSON table the command writes, and the claims in the run's scorecard.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

SCENARIO = "moved_while_watched"
RUN_TIMEOUT = 420.0


@pytest.mark.ros
@pytest.mark.timeout(480)
def test_an_object_moved_while_the_camera_watches_keeps_its_symbol(tmp_path) -> None:
    output = tmp_path / "suite"
    command = [str(Path(sys.executable).parent / "sailor"), "demo", "--scenario", SCENARIO, "--seed", "0",
               "--output", str(output), "--deadline", "360"]
    environment = {key: value for key, value in os.environ.items() if key != "ROS_DOMAIN_ID"}
    completed = subprocess.run(command, capture_output=True, text=True, timeout=RUN_TIMEOUT, env=environment,
                               stdin=subprocess.DEVNULL)
    log = completed.stdout[-6000:] + completed.stderr[-2000:]
    table = json.loads((output / "scenarios.json").read_text())
    (run,) = table["runs"]
    assert run["scenario"] == SCENARIO and run["ending"] == "ended", log
    assert run["right"], (run, log)
    assert completed.returncode == 0, log
    verdict = run["verdict"]
    assert verdict["outcome"].startswith("found as cup_") and verdict["claimed"] == "red_mug"
    assert verdict["duplicates"] == 0, verdict
    card = json.loads((Path(run["folder"]) / "report" / "scorecard.json").read_text())
    claims = card["claims"]
    symbol = claims["target_symbol"]
    assert symbol == claims["symbols_before"]["red_mug"]  # the symbol it had before it moved
    assert claims["refers_to"][symbol] == "red_mug" and claims["object_at"][symbol] == ["kitchen"]
    events = json.loads((Path(run["folder"]) / "ground_truth.json").read_text())["events"]
    assert [(event["name"], event["action"]) for event in events] == [("red_mug_slides_along_the_table", "move")]
    assert "scenario  " in completed.stdout and f"{SCENARIO}  0" in completed.stdout  # the printed table
