"""The bag round trip: the simulated house recorded live (``sailor launch house --record``), then
replayed offline (``sailor replay bag``) with the same launch file's parameters, gives the
anchors the live anchoring node ended with: the same symbols, within 2 cm."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from merlin2_sailor.ros.bags import BagReader

pytestmark = pytest.mark.ros

SAILOR = str(Path(sys.executable).parent / "sailor")
RECORD_SECONDS = 12.0
CONFIRMED = 1  # merlin2_sailor_interfaces/Anchor STATE_CONFIRMED


def live_anchors(bag: Path) -> dict[str, tuple[str, np.ndarray]]:
    """The confirmed anchors of the last AnchorArray the live anchoring node published."""
    last = None
    with BagReader(bag) as reader:
        for item in reader.messages(["/anchors"]):
            last = item.message
    assert last is not None, "the bag holds no /anchors"
    return {anchor.symbol: (anchor.class_name, np.array([anchor.position.x, anchor.position.y, anchor.position.z]))
            for anchor in last.anchors if anchor.state == CONFIRMED}


def test_a_bag_of_the_house_replays_offline_to_the_live_anchors(tmp_path) -> None:
    bag = tmp_path / "bag"
    environment = {**os.environ, "SAILOR_DATA": str(tmp_path / "house")}
    launch = subprocess.run([SAILOR, "launch", "house", "--duration", str(RECORD_SECONDS), "--record", str(bag)],
                            env=environment, capture_output=True, text=True, timeout=180, stdin=subprocess.DEVNULL)
    assert launch.returncode == 0, launch.stdout[-4000:] + launch.stderr[-2000:]
    assert f"bag {bag} closed" in launch.stdout, launch.stdout[-4000:]
    with BagReader(bag) as reader:
        recorded = set(reader.topics)
    assert {"/camera/color/image_raw", "/camera/depth/image_raw", "/camera/detections", "/camera/percepts",
            "/anchors", "/anchor_events", "/merlin2/knowledge_changes"} <= recorded

    output = tmp_path / "replay"
    replay = subprocess.run([SAILOR, "replay", "bag", str(bag), "--launch", "house", "--output", str(output),
                             "--no-video"], capture_output=True, text=True, timeout=300, stdin=subprocess.DEVNULL)
    assert replay.returncode == 0, replay.stdout[-3000:] + replay.stderr[-2000:]
    replayed = {anchor["symbol"]: (anchor["class"], np.array(anchor["position_m"]))
                for anchor in json.loads((output / "anchors.json").read_text())["anchors"]
                if anchor["state"] == "confirmed"}
    live = live_anchors(bag)
    assert live, "the live run confirmed no anchor"
    assert sorted(replayed) == sorted(live), replay.stdout[-3000:]
    for symbol, (class_name, position) in live.items():
        assert replayed[symbol][0] == class_name
        assert np.linalg.norm(replayed[symbol][1] - position) < 0.02, (symbol, replayed[symbol][1], position)
