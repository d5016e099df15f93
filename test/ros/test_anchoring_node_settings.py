"""One YAML drives the anchoring node and the offline tools identically.

The node is started in this process (rclpy, a context of its own) from the command line
``sailor launch`` would give it, and its settings are compared with what the loader that
``sailor replay`` and ``sailor evaluate`` use builds from the same files. Also: the node declares
every setting with its descriptor, and converts frozen views to the same messages as anchors.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest
import rclpy
import yaml
from rcl_interfaces.msg import ParameterType
from std_msgs.msg import Header

from merlin2_sailor.anchoring.anchor import Anchor, AnchorState
from merlin2_sailor.anchoring.anchor_view import AnchorView
from merlin2_sailor.anchoring.settings import SETTINGS, default_settings, load_anchoring_settings
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.launcher import load_launch_file
from merlin2_sailor.launcher.command import build_command
from merlin2_sailor.ros.anchoring_node import AnchoringNode
from merlin2_sailor.ros.conversions.anchoring import anchor_markers, anchors_to_message

pytestmark = pytest.mark.ros

REPOSITORY = Path(__file__).resolve().parents[2]
CONFIG = REPOSITORY / "config" / "anchoring.yaml"
#: A few values that differ from every default, of every type and in nested parts of the tree.
CHANGED = {"forget_after": 120.0, "visible_range": 4.0, "match_threshold": 0.6, "rules_position_sigma": 1.2,
           "rules_maximum_sigma": 1.5, "confirm_after": 4, "gate_class_mismatch": False, "world_frame": "odom",
           "reappearance_distance": 0.1, "track_period": 0.25}


@contextmanager
def anchoring_node(arguments: Sequence[str]) -> Iterator[AnchoringNode]:
    """An AnchoringNode in this process, started with ``arguments`` (``--ros-args ...``)."""
    context = rclpy.Context()
    rclpy.init(args=["anchoring", *arguments], context=context)
    node = None
    try:
        node = AnchoringNode(context=context)
        yield node
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.shutdown(context=context)


def test_the_node_and_the_offline_loader_build_the_same_settings_from_one_yaml(tmp_path) -> None:
    robot = tmp_path / "robot.yaml"
    offline = {"knowledge_base": "", "state_folder": str(tmp_path / "state")}
    robot.write_text(yaml.safe_dump({"/**/anchoring": {"ros__parameters": {**CHANGED, **offline}}}))
    with anchoring_node(["--ros-args", "--params-file", str(CONFIG), "--params-file", str(robot)]) as node:
        from_node = node.service.settings
    loaded = load_anchoring_settings(CONFIG, robot)
    assert from_node.core == loaded.core  # the AnchoringConfig, every part
    assert from_node == loaded  # and the matcher, the persistence and the timing
    assert from_node.core != default_settings().core
    assert from_node.core.lifecycle.forget_after == 120.0 and from_node.matcher.rules.maximum_sigma == 1.5


def test_a_launch_files_anchoring_node_and_sailor_replay_see_the_same_settings(tmp_path) -> None:
    (spec,) = [node for node in load_launch_file(REPOSITORY / "launch" / "house.yaml").nodes
               if node.executable == "anchoring"]
    # The house's files and values, and this test's: no knowledge base, a private state folder.
    spec = dataclasses.replace(spec, parameters=(
        *spec.parameters, {"knowledge_base": "", "state_folder": str(tmp_path / "state"), "confirm_after": 2}))
    command = build_command(spec, tmp_path)  # exactly what `sailor launch house` runs
    with anchoring_node(command[command.index("--ros-args"):]) as node:
        from_node = node.service.settings
    loaded = load_anchoring_settings(*spec.parameters)
    assert from_node == loaded
    assert (loaded.matcher.rules.maximum_sigma, loaded.core.visibility.frustum.far) == (0.3, 4.5)
    assert loaded.core.lifecycle.confirm_after == 2


def test_every_setting_is_declared_with_its_descriptor_and_a_bad_one_is_refused_by_both(tmp_path) -> None:
    with anchoring_node(["--ros-args", "-p", "knowledge_base:=''", "-p", "state_folder:=''"]) as node:
        for row in SETTINGS:
            descriptor = node.describe_parameter(row.name)
            assert descriptor.read_only and descriptor.description.startswith(row.description), row.name
            if isinstance(row.default, float) and row.minimum is not None:
                (bounds,) = descriptor.floating_point_range
                assert (bounds.from_value, bounds.to_value) == (row.minimum, row.maximum), row.name
            if isinstance(row.default, bool):
                assert descriptor.type == ParameterType.PARAMETER_BOOL
    bad = tmp_path / "bad.yaml"
    bad.write_text("anchoring:\n  ros__parameters: {matcher: neural, knowledge_base: '', state_folder: ''}\n")
    with pytest.raises(ConfigurationError, match="must be one of network, rules, got 'neural'"):
        load_anchoring_settings(bad)
    with pytest.raises(ConfigurationError, match="must be one of network, rules, got 'neural'"):
        with anchoring_node(["--ros-args", "--params-file", str(bad)]):
            pass


def test_views_convert_to_the_messages_their_anchors_convert_to() -> None:
    anchor = Anchor(symbol="cup_1", class_name="cup", position=np.array([1.0, 2.0, 0.8]),
                    size=np.array([0.1, 0.1, 0.12]), first_seen=3.0, last_seen=4.5, state=AnchorState.MISSING,
                    times_seen=7, last_tracker_id="12", indistinguishable_from=("cup_4",),
                    found_by_look_alone="cup_9")
    header = Header(frame_id="map")
    view = AnchorView.of(anchor)
    assert anchors_to_message([view], header) == anchors_to_message([anchor], header)
    assert anchors_to_message([view], header).anchors[0].found_by_look_alone == "cup_9"
    assert anchor_markers([view], header) == anchor_markers([anchor], header)
    anchor.position[0] = 9.0  # the view is a copy: its message does not move with the anchor
    assert anchors_to_message([view], header).anchors[0].position.x == 1.0
