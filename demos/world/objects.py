"""The movable objects of the world: what the house file says about one, and its live state.

An object is an axis-aligned box standing on whatever is under its footprint's centre (a table
top, a shelf, the floor), so the file gives only (x, y) and the height follows from the house.
Its class is the COCO name a detector would say ("cup", "teddy bear"), checked against the
detector's label table so that a typo cannot create a class nothing ever detects.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.perception.coco_labels import COCO_TF_LABELS
from merlin2_sailor_demos.world.geometry import Box
from merlin2_sailor_demos.world.yaml_fields import Fields

COCO_CLASS_IDS = {name: class_id for class_id, name in COCO_TF_LABELS.items()}


@dataclass(frozen=True, slots=True)
class ObjectSpec:
    """An object as a world file (or a scenario's ``add`` event) describes it."""

    id: str
    class_name: str
    xy: tuple[float, float]
    size: tuple[float, float, float]
    texture: str

    @property
    def class_id(self) -> int:
        return COCO_CLASS_IDS[self.class_name]

    @classmethod
    def from_mapping(cls, data: Any, where: str, textures: set[str] | None = None) -> ObjectSpec:
        fields = Fields(data, where, ("id", "class", "position", "size", "texture"))
        object_id = fields.text("id")
        where = f"{where} ({object_id})"
        class_name = fields.text("class")
        if class_name not in COCO_CLASS_IDS:
            raise ConfigurationError(
                f"{where}: class '{class_name}' is not a COCO class the detectors know; use the COCO spelling "
                "(e.g. 'cup', 'teddy bear', 'potted plant')"
            )
        texture = fields.text("texture")
        if textures is not None and texture not in textures:
            raise ConfigurationError(f"{where}: texture '{texture}' is not defined; textures: {sorted(textures)}")
        x, y = fields.vector("position", 2)
        return cls(object_id, class_name, (x, y), fields.vector("size", 3, positive=True), texture)


@dataclass(eq=False)
class WorldObject:
    """The live state of one object: where its centre is now, and whether the gripper holds it."""

    id: str
    class_name: str
    size: tuple[float, float, float]
    texture: str
    position: np.ndarray  # (3,) centre, world frame, metres
    carried: bool = False

    @property
    def class_id(self) -> int:
        return COCO_CLASS_IDS[self.class_name]

    @property
    def box(self) -> Box:
        return Box(tuple(float(v) for v in self.position), self.size)

    def as_dict(self) -> dict[str, Any]:
        return {
            "id": self.id,
            "class": self.class_name,
            "position": [round(float(value), 4) for value in self.position],
            "size": list(self.size),
            "carried": self.carried,
        }
