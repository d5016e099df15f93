"""The launch description: which nodes to start, with which names, parameters and remappings.

A launch file is YAML, so it is data that users can read and edit without learning a launch API::

    nodes:
      - executable: rgbd_player        # a console script of this or another installed package
        name: camera                   # node name (optional: the node's default)
        namespace: robot               # optional
        parameters:                    # parameter files (relative to the launch file) or values
          - ../config/rgbd_player.yaml
          - {rate_hz: 15.0}
        remappings: {color/image_raw: /camera/color/image_raw}
        arguments: []                  # extra command-line arguments before --ros-args
        on_exit: shutdown              # shutdown (default): this node's exit stops the launch
                                       # ignore: let it exit (a one-shot tool)
    environment: {SOME_VARIABLE: value}  # optional, for every node

Errors name the file and the offending entry, because a launch file is usually edited by hand.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from enum import Enum
from pathlib import Path
from typing import Any

import yaml

from merlin2_sailor.errors import ConfigurationError


class ExitPolicy(Enum):
    """What the launch does when a node's process ends."""

    SHUTDOWN = "shutdown"  # stop every other node: the graph cannot work without this one
    IGNORE = "ignore"  # let it go: a one-shot tool whose end is expected


@dataclass(frozen=True)
class NodeSpec:
    """One node to start. ``parameters`` holds resolved file paths and inline value mappings."""

    executable: str
    name: str = ""
    namespace: str = ""
    parameters: tuple[Path | dict[str, Any], ...] = ()
    remappings: tuple[tuple[str, str], ...] = ()
    arguments: tuple[str, ...] = ()
    on_exit: ExitPolicy = ExitPolicy.SHUTDOWN

    @property
    def label(self) -> str:
        """The name its log lines are prefixed with: the node name, else the executable."""
        return self.name or self.executable


@dataclass(frozen=True)
class LaunchSpec:
    """A whole launch description."""

    nodes: tuple[NodeSpec, ...]
    environment: dict[str, str] = field(default_factory=dict)
    source: Path | None = None


_NODE_KEYS = {"executable", "name", "namespace", "parameters", "remappings", "arguments", "on_exit"}
_TOP_LEVEL_KEYS = {"nodes", "environment"}


def load_launch_file(path: str | os.PathLike[str]) -> LaunchSpec:
    """Read and validate a launch file; raise ConfigurationError saying what to fix."""
    path = Path(path)
    if not path.is_file():
        raise ConfigurationError(f"launch file {path} does not exist")
    try:
        document = yaml.safe_load(path.read_text())
    except yaml.YAMLError as error:
        raise ConfigurationError(f"{path} is not valid YAML: {error}") from error
    return parse_launch_document(document, base_directory=path.parent.resolve(), source=path)


def parse_launch_document(
    document: Any, base_directory: Path, source: Path | None = None
) -> LaunchSpec:
    """Validate an already-parsed launch document; relative paths resolve against base_directory."""
    where = str(source) if source else "launch description"
    if not isinstance(document, dict):
        raise ConfigurationError(f"{where}: expected a mapping with a 'nodes' list at the top")
    _reject_unknown_keys(document, _TOP_LEVEL_KEYS, where)
    raw_nodes = document.get("nodes")
    if not isinstance(raw_nodes, list) or not raw_nodes:
        raise ConfigurationError(f"{where}: 'nodes' must be a non-empty list of nodes")
    environment = document.get("environment") or {}
    if not isinstance(environment, dict):
        raise ConfigurationError(f"{where}: 'environment' must map variable names to values")
    nodes = tuple(
        _parse_node(raw, f"{where}: nodes[{index}]", base_directory)
        for index, raw in enumerate(raw_nodes)
    )
    labels = [node.label if not node.namespace else f"{node.namespace}/{node.label}" for node in nodes]
    duplicates = sorted({label for label in labels if labels.count(label) > 1})
    if duplicates:
        raise ConfigurationError(
            f"{where}: node names must be unique; give a distinct 'name' to {', '.join(duplicates)}"
        )
    return LaunchSpec(
        nodes=nodes,
        environment={str(key): _expand(str(value)) for key, value in environment.items()},
        source=source,
    )


def _parse_node(raw: Any, where: str, base_directory: Path) -> NodeSpec:
    if not isinstance(raw, dict):
        raise ConfigurationError(f"{where}: each node must be a mapping with an 'executable'")
    _reject_unknown_keys(raw, _NODE_KEYS, where)
    executable = raw.get("executable")
    if not isinstance(executable, str) or not executable.strip():
        raise ConfigurationError(f"{where}: 'executable' is required (a console script name)")
    try:
        on_exit = ExitPolicy(raw.get("on_exit", ExitPolicy.SHUTDOWN.value))
    except ValueError:
        choices = ", ".join(policy.value for policy in ExitPolicy)
        raise ConfigurationError(f"{where}: 'on_exit' must be one of {choices}") from None
    return NodeSpec(
        executable=executable.strip(),
        name=_optional_string(raw, "name", where),
        namespace=_optional_string(raw, "namespace", where),
        parameters=_parse_parameters(raw.get("parameters") or [], where, base_directory),
        remappings=_parse_remappings(raw.get("remappings") or {}, where),
        arguments=tuple(_expand(str(argument)) for argument in raw.get("arguments") or []),
        on_exit=on_exit,
    )


def _parse_parameters(
    raw: Any, where: str, base_directory: Path
) -> tuple[Path | dict[str, Any], ...]:
    if isinstance(raw, (str, dict)):
        raw = [raw]
    if not isinstance(raw, list):
        raise ConfigurationError(f"{where}: 'parameters' must be a list of files and mappings")
    parameters: list[Path | dict[str, Any]] = []
    for entry in raw:
        if isinstance(entry, dict):
            parameters.append({str(key): _expand_values(value) for key, value in entry.items()})
        elif isinstance(entry, str):
            file = Path(_expand(entry))
            file = file if file.is_absolute() else (base_directory / file).resolve()
            if not file.is_file():
                raise ConfigurationError(f"{where}: parameters file {file} does not exist")
            parameters.append(file)
        else:
            raise ConfigurationError(
                f"{where}: a 'parameters' entry must be a file path or a mapping, got {entry!r}"
            )
    return tuple(parameters)


def _parse_remappings(raw: Any, where: str) -> tuple[tuple[str, str], ...]:
    if isinstance(raw, dict):
        pairs = list(raw.items())
    elif isinstance(raw, list) and all(isinstance(item, dict) and len(item) == 1 for item in raw):
        pairs = [next(iter(item.items())) for item in raw]
    else:
        raise ConfigurationError(f"{where}: 'remappings' must map each 'from' name to a 'to' name")
    return tuple((str(source), str(target)) for source, target in pairs)


def _optional_string(raw: dict[str, Any], key: str, where: str) -> str:
    value = raw.get(key, "")
    if not isinstance(value, str):
        raise ConfigurationError(f"{where}: '{key}' must be a string")
    return value.strip().strip("/") if key == "namespace" else value.strip()


def _reject_unknown_keys(raw: dict[str, Any], allowed: set[str], where: str) -> None:
    unknown = sorted(set(map(str, raw)) - allowed)
    if unknown:
        raise ConfigurationError(
            f"{where}: unknown key(s) {', '.join(unknown)}; allowed: {', '.join(sorted(allowed))}"
        )


_VARIABLE = re.compile(r"\$\{(?P<name>[A-Za-z_][A-Za-z0-9_]*)(?::-(?P<default>[^}]*))?\}")


def _expand(text: str) -> str:
    """Expand ``${VARIABLE}``, ``${VARIABLE:-default}`` and a leading ``~``.

    An unset variable without a default is an error: left as text, it would silently become a
    file or folder literally named ``${VARIABLE}``.
    """

    def substitute(match: re.Match[str]) -> str:
        name, default = match.group("name"), match.group("default")
        if name in os.environ:
            return os.environ[name]
        if default is not None:
            return os.path.expanduser(default)
        raise ConfigurationError(
            f"environment variable {name} is not set; set it, or write ${{{name}:-default}}"
        )

    return os.path.expanduser(_VARIABLE.sub(substitute, text))


def _expand_values(value: Any) -> Any:
    """Expand variables in every string of an inline parameter value (lists included)."""
    if isinstance(value, str):
        return _expand(value)
    if isinstance(value, list):
        return [_expand_values(item) for item in value]
    return value
