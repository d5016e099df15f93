"""``sailor launch`` starts a real two-node graph, shows its output, and stops it cleanly."""

from __future__ import annotations

import re
import signal
import subprocess
import sys
import threading
from pathlib import Path

import pytest

pytestmark = pytest.mark.ros

SAILOR = str(Path(sys.executable).parent / "sailor")


def test_launch_starts_both_nodes_and_ctrl_c_stops_them_cleanly(tmp_path, ros_probe) -> None:
    launch_file = tmp_path / "graph.yaml"
    launch_file.write_text(
        "nodes:\n"
        "  - {executable: rgbd_player, namespace: launched, parameters: [{rate_hz: 10.0}]}\n"
        "  - {executable: topic_monitor, name: launched_monitor,\n"
        "     parameters: [{report_period: 0.5, topics: [/launched/color/image_raw]}]}\n"
    )
    process = subprocess.Popen([SAILOR, "launch", str(launch_file)], stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, text=True)
    lines: list[str] = []
    reader = threading.Thread(target=lambda: lines.extend(iter(process.stdout.readline, "")), daemon=True)
    reader.start()
    image_rate = re.compile(r"/launched/color/image_raw (\d+\.\d) Hz")

    def monitor_reports_images() -> bool:
        rates = [float(match.group(1)) for line in list(lines) for match in image_rate.finditer(line)]
        return bool(rates) and max(rates) > 5.0  # published at 10 Hz

    try:
        both_joined = ros_probe.wait_for(
            lambda: {"/launched/rgbd_player", "/launched_monitor"} <= ros_probe.node_names())
        images_flowed = ros_probe.wait_for(monitor_reports_images)
    finally:
        process.send_signal(signal.SIGINT)
        process.wait(timeout=30)
        reader.join(timeout=5)
    output = "".join(lines)
    assert both_joined, output
    assert images_flowed, output
    summary_start = next(i for i, line in enumerate(lines) if line.startswith("launch ended:"))
    assert all(line.startswith("[") for line in lines[:summary_start]), output
    assert "[rgbd_player]" in output and "[launched_monitor]" in output
    assert "received SIGINT" in output and "all nodes ended cleanly" in output, output
    assert process.returncode == 0
    assert ros_probe.wait_for(lambda: "/launched_monitor" not in ros_probe.node_names(), timeout=10.0)


def test_launch_reports_a_bad_file_in_one_line_without_a_traceback(tmp_path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("nodes:\n  - {name: nothing}\n")
    completed = subprocess.run([SAILOR, "launch", str(bad)], capture_output=True, text=True, timeout=60)
    assert completed.returncode == 2
    assert "'executable' is required" in completed.stderr
    assert "Traceback" not in completed.stderr


def test_help_lists_the_subcommands() -> None:
    completed = subprocess.run([SAILOR, "--help"], capture_output=True, text=True, timeout=60)
    assert completed.returncode == 0 and "launch" in completed.stdout
