"""Turn a NodeSpec into the command line that starts it.

Every ROS 2 node understands the same ``--ros-args`` grammar (``-r __node:=``, ``-r __ns:=``,
``--params-file``, ``-r from:=to``), so a node needs no launch API to be configured: its command
line says everything. Inline parameter values are written to a parameters file because YAML
values (lists, nested strings) do not survive ``-p name:=value`` quoting reliably.
"""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

import yaml

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.launcher.spec import NodeSpec


def resolve_executable(executable: str) -> str:
    """Find an executable: a path, this interpreter's scripts folder, PATH, or an ament prefix.

    The interpreter's own folder comes first so that a launch started from a virtual environment
    runs that environment's nodes even when the venv is not activated. The ament prefixes cover
    packages built with colcon, whose nodes live in ``<prefix>/lib/<package>/``.
    """
    if os.sep in executable:
        path = Path(executable).expanduser()
        if path.is_file() and os.access(path, os.X_OK):
            return str(path.resolve())
        raise ConfigurationError(f"executable {executable} does not exist or is not executable")
    scripts_directory = Path(sys.executable).parent
    candidate = scripts_directory / executable
    if candidate.is_file() and os.access(candidate, os.X_OK):
        return str(candidate)
    found = shutil.which(executable)
    if found:
        return found
    for prefix in filter(None, os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep)):
        for candidate in sorted(Path(prefix, "lib").glob(f"*/{executable}")):
            if candidate.is_file() and os.access(candidate, os.X_OK):
                return str(candidate)
    raise ConfigurationError(
        f"executable '{executable}' not found in {scripts_directory}, on PATH or in the ament "
        "prefixes; check the name in the launch file, or run scripts/setup.sh to install the nodes"
    )


def build_command(node: NodeSpec, scratch_directory: Path) -> list[str]:
    """Return the argv that starts ``node``; inline parameters go to files in scratch_directory."""
    command = [resolve_executable(node.executable), *node.arguments]
    ros_arguments: list[str] = []
    if node.name:
        ros_arguments += ["-r", f"__node:={node.name}"]
    if node.namespace:
        ros_arguments += ["-r", f"__ns:=/{node.namespace}"]
    for index, parameters in enumerate(node.parameters):
        if isinstance(parameters, Path):
            file = parameters
        else:
            file = scratch_directory / f"{_file_safe(node.label)}_parameters_{index}.yaml"
            file.write_text(yaml.safe_dump({"/**": {"ros__parameters": parameters}}))
        ros_arguments += ["--params-file", str(file)]
    for source, target in node.remappings:
        ros_arguments += ["-r", f"{source}:={target}"]
    if ros_arguments:
        command += ["--ros-args", *ros_arguments]
    return command


def _file_safe(text: str) -> str:
    return "".join(character if character.isalnum() else "_" for character in text)
