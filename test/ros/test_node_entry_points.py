"""Every node the package installs starts as a process, appears in the graph, and stops cleanly.

The list comes from the installed entry points, so a node added to setup.py is tested here
without anyone remembering to add it.
"""

from __future__ import annotations

from importlib.metadata import distribution

import pytest

TOOLS = {"sailor"}
#: What a node writes goes into the test's folder, not the working directory.
OUTPUT_PARAMETERS = {"bag_recorder": "path:={folder}/bag"}
NODE_EXECUTABLES = sorted(
    entry.name for entry in distribution("merlin2_sailor").entry_points
    if entry.group == "console_scripts" and entry.name not in TOOLS
)


def test_the_package_installs_nodes() -> None:
    assert {"rgbd_player", "topic_monitor"} <= set(NODE_EXECUTABLES)


@pytest.mark.ros
@pytest.mark.parametrize("executable", NODE_EXECUTABLES)
def test_node_starts_joins_the_graph_and_shuts_down_cleanly(executable, ros_probe, node_process, tmp_path) -> None:
    node_name = f"entry_point_test_{executable}"
    output = ["-p", OUTPUT_PARAMETERS[executable].format(folder=tmp_path)] if executable in OUTPUT_PARAMETERS else []
    process = node_process(executable, "--ros-args", "-r", f"__node:={node_name}", *output)
    joined = ros_probe.wait_for_node(f"/{node_name}")
    exit_code = process.stop()
    assert joined, f"{executable} never appeared in the graph; its output:\n{process.text}"
    assert exit_code == 0, process.text
    assert "Traceback" not in process.text
    assert ros_probe.wait_for(lambda: f"/{node_name}" not in ros_probe.node_names(), timeout=10.0)


def test_malformed_ros_arguments_are_one_line_not_a_traceback(node_process) -> None:
    process = node_process("topic_monitor", "--ros-args", "-p", "window:=")
    process.process.wait(timeout=30.0)
    assert process.stop() == 2
    assert "invalid ROS arguments" in process.text and "Traceback" not in process.text
