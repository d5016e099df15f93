"""A world file that extends another: the base world with objects added, removed or changed.

A scenario of the house differs from the house in a few objects and events, so its file names
the base and lists only the differences instead of copying 300 lines::

    extends: ../house.yaml          # relative to this file
    remove_objects: [book_1]        # ids of the base's objects to leave out
    objects:                        # merged by id: a base id changes only the fields given,
      - {id: red_mug, position: [1.5, 6.2]}                                      # a new id adds
      - {id: red_mug_2, class: cup, position: [2.3, 2.1], size: [0.1, 0.1, 0.11], texture: red_mug}
    robot: {start: hall}            # mapping sections merge key by key (lists are replaced)
    scenario: [...]                 # replaces the base's events (absent: the base's are kept)

``description`` and ``mission`` describe the file they are in and are never inherited. A base
may itself extend another; a cycle is an error. The result is one plain mapping, checked as any
world file is, so an extension can break nothing the checks would not catch in a full file.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml

from merlin2_sailor.errors import ConfigurationError

EXTENDS = "extends"
REMOVE_OBJECTS = "remove_objects"
#: Sections of a file that describe that file only: an extension never inherits them.
OWN_SECTIONS = ("description", "mission")


def read_world_mapping(path: Path) -> dict[str, Any]:
    """The YAML mapping of ``path`` with every ``extends`` resolved (the file's own errors named)."""
    return _resolve(path.resolve(), ())


def _load_yaml(path: Path) -> Any:
    try:
        return yaml.safe_load(path.read_text(encoding="utf-8"))
    except OSError as error:
        raise ConfigurationError(f"cannot read world file {path}: {error.strerror or error}") from error
    except yaml.YAMLError as error:
        raise ConfigurationError(f"world file {path} is not valid YAML: {error}") from error


def _resolve(path: Path, chain: tuple[Path, ...]) -> dict[str, Any]:
    if path in chain:
        names = " -> ".join(item.name for item in (*chain, path))
        raise ConfigurationError(f"world files extend each other in a cycle: {names}")
    data = _load_yaml(path)
    if not isinstance(data, Mapping):
        raise ConfigurationError(f"{path.name}: expected a mapping of sections, got {type(data).__name__}")
    if EXTENDS not in data:
        if REMOVE_OBJECTS in data:
            raise ConfigurationError(f"{path.name}: '{REMOVE_OBJECTS}' needs '{EXTENDS}' (a base to remove from)")
        return dict(data)
    base_name = data[EXTENDS]
    if not isinstance(base_name, str) or not base_name.strip():
        raise ConfigurationError(f"{path.name}: '{EXTENDS}' must name a world file, got {base_name!r}")
    base_path = (path.parent / base_name.strip()).resolve()
    if not base_path.is_file():
        raise ConfigurationError(f"{path.name}: extends {base_name}, which does not exist ({base_path})")
    base = {key: value for key, value in _resolve(base_path, (*chain, path)).items() if key not in OWN_SECTIONS}
    return extend(base, data, path.name)


def extend(base: Mapping[str, Any], changes: Mapping[str, Any], where: str) -> dict[str, Any]:
    """``base`` with ``changes`` applied (the rules of the module docstring); ``where`` names errors."""
    merged = dict(base)
    for key, value in changes.items():
        if key in (EXTENDS, REMOVE_OBJECTS, "objects"):
            continue
        if key == "scenario" or key in OWN_SECTIONS:
            merged[key] = value
        elif isinstance(value, Mapping) and isinstance(merged.get(key), Mapping):
            merged[key] = _deep_merge(merged[key], value)
        else:
            merged[key] = value
    merged["objects"] = _merge_objects(base.get("objects") or [], changes.get(REMOVE_OBJECTS) or [],
                                       changes.get("objects") or [], where)
    return merged


def _deep_merge(base: Mapping[str, Any], changes: Mapping[str, Any]) -> dict[str, Any]:
    merged = dict(base)
    for key, value in changes.items():
        if isinstance(value, Mapping) and isinstance(merged.get(key), Mapping):
            merged[key] = _deep_merge(merged[key], value)
        else:
            merged[key] = value
    return merged


def _merge_objects(base: Any, removals: Any, changes: Any, where: str) -> list[Any]:
    if not isinstance(base, list):
        raise ConfigurationError(f"{where}: the base world's 'objects' must be a list")
    if not isinstance(removals, list) or not all(isinstance(item, str) for item in removals):
        raise ConfigurationError(f"{where}: '{REMOVE_OBJECTS}' must be a list of object ids, got {removals!r}")
    if not isinstance(changes, list):
        raise ConfigurationError(f"{where}: 'objects' must be a list, got {type(changes).__name__}")
    by_id = {item.get("id"): dict(item) for item in base if isinstance(item, Mapping)}
    order = [item.get("id") for item in base if isinstance(item, Mapping)]
    for object_id in removals:
        if object_id not in by_id:
            raise ConfigurationError(f"{where}: {REMOVE_OBJECTS} names '{object_id}', which the base does not have "
                                     f"(objects: {sorted(str(i) for i in by_id)})")
        del by_id[object_id]
        order.remove(object_id)
    for index, item in enumerate(changes):
        if not isinstance(item, Mapping) or not isinstance(item.get("id"), str):
            raise ConfigurationError(f"{where}: objects[{index}] must be a mapping with an 'id'")
        object_id = item["id"]
        if object_id in removals:
            raise ConfigurationError(f"{where}: objects[{index}] changes '{object_id}', which {REMOVE_OBJECTS} "
                                     "removes")
        if object_id in by_id:
            by_id[object_id] = {**by_id[object_id], **item}
        else:
            by_id[object_id] = dict(item)
            order.append(object_id)
    return [by_id[object_id] for object_id in order]
