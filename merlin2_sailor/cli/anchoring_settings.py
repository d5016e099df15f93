"""The anchoring settings options of ``sailor`` commands that run the anchoring layer offline.

``sailor replay`` and ``sailor evaluate`` build the anchoring service from the same parameter
files the anchoring node is started with, so their figures are the deployed system's:
``--launch house`` takes exactly what ``sailor launch house`` hands the node (its files and
inline values, in order), ``--params FILE`` adds parameter files, ``--set NAME=VALUE`` single
values. With none of them, config/anchoring.yaml (what every shipped launch file starts from).
"""

from __future__ import annotations

import argparse
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml

from merlin2_sailor.errors import ConfigurationError

#: The executable of the anchoring node in launch files.
ANCHORING_EXECUTABLE = "anchoring"


def add_settings_arguments(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group(
        "anchoring settings", "the anchoring node's parameters (default: config/anchoring.yaml)")
    group.add_argument("--launch", default="", metavar="NAME",
                       help="take the anchoring node's parameters from this launch file (a path, or a shipped "
                            "one: sailor, house, demo), as `sailor launch` hands them to the node")
    group.add_argument("--params", action="append", default=[], metavar="FILE",
                       help="a ROS parameter file for the anchoring node (after --launch's; repeatable; a "
                            "relative name is also looked up in config/)")
    group.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", dest="set_parameters",
                       help="one anchoring parameter, last (repeatable; the value is YAML: --set visible_range=4.5)")


def parameter_sources(arguments: argparse.Namespace) -> tuple[list[Path | dict[str, Any]], str]:
    """(the parameter files and inline mappings, in order; the node's fully qualified name)."""
    from merlin2_sailor.resources import config_file, config_path

    sources: list[Path | dict[str, Any]] = []
    node = f"/{ANCHORING_EXECUTABLE}"
    if arguments.launch:
        sources, node = launch_node_parameters(arguments.launch, ANCHORING_EXECUTABLE, "anchoring")
    for name in arguments.params:
        path = config_path(name, "anchoring.yaml")
        if not path.is_file():
            raise ConfigurationError(f"--params {name}: no such parameter file")
        sources.append(path)
    if not sources:
        sources.append(config_file("anchoring.yaml"))
    return sources, node


def launch_node_parameters(launch: str, executable: str, what: str) -> tuple[list[Path | dict[str, Any]], str]:
    """What the launch file ``launch`` hands its one node of ``executable`` (its parameter files and
    inline values, in order) and that node's fully qualified name; ``what`` names the node in errors."""
    from merlin2_sailor.launcher import load_launch_file
    from merlin2_sailor.resources import find_launch_file

    path = find_launch_file(launch)
    nodes = [spec for spec in load_launch_file(path).nodes if spec.executable == executable]
    if len(nodes) != 1:
        raise ConfigurationError(
            f"--launch {launch}: {path} starts {len(nodes)} {what} nodes; name a launch file with exactly one")
    spec = nodes[0]
    return list(spec.parameters), "/" + "/".join(part for part in (spec.namespace, spec.name or executable) if part)


def set_parameters(arguments: argparse.Namespace) -> dict[str, Any]:
    """The ``--set NAME=VALUE`` values, each value read as YAML (as ``ros2 run -p`` reads it)."""
    values: dict[str, Any] = {}
    for assignment in arguments.set_parameters:
        name, separator, text = assignment.partition("=")
        if not separator or not name.strip():
            raise ConfigurationError(f"--set {assignment!r}: write NAME=VALUE (e.g. --set visible_range=4.5)")
        try:
            values[name.strip()] = yaml.safe_load(text)
        except yaml.YAMLError as error:
            raise ConfigurationError(f"--set {assignment!r}: the value is not YAML: {error}") from error
    return values


def settings_from_arguments(arguments: argparse.Namespace, overrides: Mapping[str, Any] | None = None) -> Any:
    """The :class:`~merlin2_sailor.anchoring.settings.AnchoringSettings` the options name, offline
    (no knowledge base, no state on disk), with ``overrides`` and then the ``--set`` values."""
    from merlin2_sailor.anchoring.settings import OFFLINE_OVERRIDES, load_anchoring_settings

    sources, node = parameter_sources(arguments)
    return load_anchoring_settings(
        *sources, overrides={**OFFLINE_OVERRIDES, **(overrides or {}), **set_parameters(arguments)}, node=node)
