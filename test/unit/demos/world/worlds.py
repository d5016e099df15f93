"""Example worlds shared by the world tests: the shipped house, and small rooms built to measure."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from merlin2_sailor_demos.world.world_file import WorldDescription

REPOSITORY_ROOT = Path(__file__).resolve().parents[4]
HOUSE_FILE = REPOSITORY_ROOT / "config" / "worlds" / "house.yaml"
HOUSE_GROUNDING_FILE = REPOSITORY_ROOT / "config" / "worlds" / "house_grounding.yaml"

MUG_TEXTURE = {"photo": "skimage/coffee", "crop": [173, 13, 411, 239]}
NO_DEPTH_NOISE = {"noise_base": 0.0, "noise_quadratic": 0.0, "dropout": 0.0}


def room_mapping(objects: Sequence[dict[str, Any]] = (), furniture: Sequence[dict[str, Any]] = (),
                 size: tuple[float, float] = (8.0, 4.0), start: Sequence[float] = (1.0, 2.0, 0.0),
                 scenario: Sequence[dict[str, Any]] = (), depth_sensor: dict[str, Any] | None = None,
                 **sections: Any) -> dict[str, Any]:
    """One empty room [0, size[0]] x [0, size[1]] with a waypoint at ``start``, as a world-file mapping."""
    return {
        "house": {
            "rooms": [{"name": "room", "x_min": 0.0, "y_min": 0.0, "x_max": size[0], "y_max": size[1]}],
            "furniture": list(furniture),
            "waypoints": [{"name": "start", "x": start[0], "y": start[1], "yaw": start[2]}],
        },
        "textures": {"mug": MUG_TEXTURE},
        "objects": list(objects),
        "robot": {"start": list(start)},
        "depth_sensor": depth_sensor if depth_sensor is not None else dict(NO_DEPTH_NOISE),
        "scenario": list(scenario),
        **sections,
    }


def room_world(**options: Any) -> WorldDescription:
    return WorldDescription.from_mapping(room_mapping(**options), "test room")


def mug(object_id: str, x: float, y: float, size: Sequence[float] = (0.3, 0.3, 0.3)) -> dict[str, Any]:
    return {"id": object_id, "class": "cup", "position": [x, y], "size": list(size), "texture": "mug"}
