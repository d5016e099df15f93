"""The launch description: parsing, validation messages, and the command lines it produces."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
import yaml

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.launcher.command import build_command, resolve_executable
from merlin2_sailor.launcher.spec import ExitPolicy, load_launch_file, parse_launch_document


def write_launch(directory: Path, document: object) -> Path:
    path = directory / "graph.yaml"
    path.write_text(yaml.safe_dump(document))
    return path


def test_full_node_entry_is_parsed_with_paths_relative_to_the_launch_file(tmp_path: Path) -> None:
    (tmp_path / "config").mkdir()
    (tmp_path / "config" / "camera.yaml").write_text("/**:\n  ros__parameters: {rate_hz: 5.0}\n")
    launch = tmp_path / "launch"
    launch.mkdir()
    path = write_launch(launch, {
        "environment": {"ROS_DOMAIN_ID": 7},
        "nodes": [{
            "executable": "rgbd_player", "name": "camera", "namespace": "/robot/",
            "parameters": ["../config/camera.yaml", {"rate_hz": 2.5, "topics": ["/a", "/b"]}],
            "remappings": {"color/image_raw": "/image"}, "on_exit": "ignore",
        }],
    })
    spec = load_launch_file(path)
    node = spec.nodes[0]
    assert spec.environment == {"ROS_DOMAIN_ID": "7"}
    assert (node.executable, node.name, node.namespace) == ("rgbd_player", "camera", "robot")
    assert node.parameters[0] == (tmp_path / "config" / "camera.yaml").resolve()
    assert node.parameters[1] == {"rate_hz": 2.5, "topics": ["/a", "/b"]}
    assert node.remappings == (("color/image_raw", "/image"),)
    assert node.on_exit is ExitPolicy.IGNORE
    assert node.label == "camera"


@pytest.mark.parametrize(
    ("document", "message"),
    [
        ([], "mapping with a 'nodes' list"),
        ({"nodes": []}, "non-empty list"),
        ({"nodes": [{"name": "x"}]}, "'executable' is required"),
        ({"nodes": [{"executable": "a", "colour": "red"}]}, "unknown key(s) colour"),
        ({"nodes": [{"executable": "a", "on_exit": "explode"}]}, "'on_exit' must be one of"),
        ({"nodes": [{"executable": "a", "parameters": ["missing.yaml"]}]}, "does not exist"),
        ({"nodes": [{"executable": "a", "parameters": [3]}]}, "file path or a mapping"),
        ({"nodes": [{"executable": "a", "remappings": "x:=y"}]}, "'remappings' must map"),
        ({"nodes": [{"executable": "a"}, {"executable": "a"}]}, "names must be unique"),
    ],
)
def test_invalid_documents_are_rejected_with_a_message_saying_what_to_fix(
    tmp_path: Path, document: object, message: str
) -> None:
    with pytest.raises(ConfigurationError, match=None) as raised:
        parse_launch_document(document, base_directory=tmp_path)
    assert message in str(raised.value)


def test_missing_and_malformed_files_are_configuration_errors(tmp_path: Path) -> None:
    with pytest.raises(ConfigurationError, match="does not exist"):
        load_launch_file(tmp_path / "absent.yaml")
    broken = tmp_path / "broken.yaml"
    broken.write_text("nodes: [unclosed\n")
    with pytest.raises(ConfigurationError, match="not valid YAML"):
        load_launch_file(broken)


def test_command_line_carries_name_namespace_parameters_and_remappings(tmp_path: Path) -> None:
    parameters_file = tmp_path / "p.yaml"
    parameters_file.write_text("{}")
    spec = parse_launch_document({"nodes": [{
        "executable": sys.executable, "name": "cam", "namespace": "robot",
        "parameters": [str(parameters_file), {"rate_hz": 3.0}],
        "remappings": {"in": "/out"}, "arguments": ["--verbose"],
    }]}, base_directory=tmp_path)
    command = build_command(spec.nodes[0], tmp_path)
    assert command[:2] == [str(Path(sys.executable).resolve()), "--verbose"]
    ros_arguments = command[command.index("--ros-args") + 1:]
    assert ros_arguments[:4] == ["-r", "__node:=cam", "-r", "__ns:=/robot"]
    files = [ros_arguments[i + 1] for i, item in enumerate(ros_arguments) if item == "--params-file"]
    assert files[0] == str(parameters_file)
    assert yaml.safe_load(Path(files[1]).read_text()) == {"/**": {"ros__parameters": {"rate_hz": 3.0}}}
    assert ros_arguments[-2:] == ["-r", "in:=/out"]


def test_unknown_executable_names_the_places_searched() -> None:
    with pytest.raises(ConfigurationError, match="not found"):
        resolve_executable("no_such_node_anywhere")


def test_variables_expand_in_inline_values_with_defaults_and_unset_ones_are_errors(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("SAILOR_TEST_DATA", "/data")
    monkeypatch.delenv("SAILOR_TEST_UNSET", raising=False)
    spec = parse_launch_document({"nodes": [{"executable": "a", "parameters": [{
        "store": "sqlite://${SAILOR_TEST_DATA}/kb.db",
        "folder": "${SAILOR_TEST_UNSET:-/fallback}/anchors",
        "topics": ["${SAILOR_TEST_DATA}/a", "b"], "rate": 5.0,
    }]}]}, base_directory=tmp_path)
    assert spec.nodes[0].parameters[0] == {
        "store": "sqlite:///data/kb.db", "folder": "/fallback/anchors", "topics": ["/data/a", "b"], "rate": 5.0}
    with pytest.raises(ConfigurationError, match="SAILOR_TEST_UNSET is not set"):
        parse_launch_document({"nodes": [{"executable": "a", "parameters": [
            {"store": "${SAILOR_TEST_UNSET}/kb.db"}]}]}, base_directory=tmp_path)
