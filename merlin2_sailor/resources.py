"""Find the package's installed data: config/ and launch/ files.

The same code runs from a source checkout installed in editable mode (the venv set-up), from a
regular pip install (files under ``<prefix>/share/merlin2_sailor``) and from a colcon workspace
(found through the ament index). Looking in that order means a developer's edits to config/ take
effect at once.
"""

from __future__ import annotations

import sys
from pathlib import Path

from merlin2_sailor.errors import ConfigurationError

PACKAGE_NAME = "merlin2_sailor"


def share_directory() -> Path:
    """Return the folder that holds this package's config/ and launch/ folders."""
    source_root = Path(__file__).resolve().parent.parent
    if (source_root / "package.xml").is_file() and (source_root / "config").is_dir():
        return source_root
    installed = Path(sys.prefix) / "share" / PACKAGE_NAME
    if installed.is_dir():
        return installed
    try:
        from ament_index_python.packages import get_package_share_directory

        return Path(get_package_share_directory(PACKAGE_NAME))
    except Exception as error:  # ament_index raises its own lookup errors, or is absent
        raise ConfigurationError(
            f"cannot find the {PACKAGE_NAME} share folder (looked in {source_root}, {installed} and "
            "the ament index); reinstall the package"
        ) from error


def config_file(name: str) -> Path:
    """Return the path of config/<name>, failing clearly when it does not exist."""
    path = share_directory() / "config" / name
    if not path.is_file():
        raise ConfigurationError(f"configuration file {path} does not exist")
    return path


def config_path(value: str, default_name: str) -> Path:
    """The file a node parameter names: a path; or, relative, one of the shipped config/ files
    (``worlds/house_grounding.yaml``), so launch files need no absolute paths; or, empty,
    config/<default_name>."""
    if not value:
        return config_file(default_name)
    path = Path(value).expanduser()
    if path.is_file() or path.is_absolute():
        return path
    shipped = share_directory() / "config" / value
    return shipped if shipped.is_file() else path


def find_launch_file(name_or_path: str) -> Path:
    """Accept a path to a launch file, or the name of one shipped in launch/ (with or without .yaml)."""
    path = Path(name_or_path).expanduser()
    if path.is_file():
        return path
    launch_directory = share_directory() / "launch"
    for candidate in (launch_directory / name_or_path, launch_directory / f"{name_or_path}.yaml"):
        if candidate.is_file():
            return candidate
    shipped = sorted(file.stem for file in launch_directory.glob("*.yaml"))
    raise ConfigurationError(
        f"no launch file '{name_or_path}': not a file, and not one of the shipped launch files "
        f"({', '.join(shipped) or 'none'})"
    )
