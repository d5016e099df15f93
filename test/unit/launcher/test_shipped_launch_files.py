"""The launch files the package ships parse, and every node they start is installed."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from merlin2_sailor.launcher.command import resolve_executable
from merlin2_sailor.launcher.spec import load_launch_file
from merlin2_sailor.resources import find_launch_file, share_directory

LAUNCH_DIRECTORY = share_directory() / "launch"


@pytest.mark.parametrize("path", sorted(LAUNCH_DIRECTORY.glob("*.yaml")), ids=lambda p: p.name)
def test_yaml_launch_file_is_valid_and_its_executables_exist(path: Path) -> None:
    spec = load_launch_file(path)
    for node in spec.nodes:
        assert Path(resolve_executable(node.executable)).is_file()


@pytest.mark.parametrize("path", sorted(LAUNCH_DIRECTORY.glob("*.launch.py")), ids=lambda p: p.name)
def test_ros2_launch_file_defines_generate_launch_description(path: Path) -> None:
    tree = ast.parse(path.read_text(), filename=str(path))
    functions = {node.name for node in tree.body if isinstance(node, ast.FunctionDef)}
    assert "generate_launch_description" in functions


def test_every_yaml_launch_file_has_a_ros2_twin() -> None:
    yaml_names = {path.name.removesuffix(".yaml") for path in LAUNCH_DIRECTORY.glob("*.yaml")}
    python_names = {path.name.removesuffix(".launch.py") for path in LAUNCH_DIRECTORY.glob("*.launch.py")}
    assert yaml_names == python_names


def test_shipped_launch_files_are_found_by_name() -> None:
    assert find_launch_file("camera") == LAUNCH_DIRECTORY / "camera.yaml"
