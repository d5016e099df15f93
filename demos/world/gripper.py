"""A simulated gripper: pick the object of a class nearest a point, carry it, put it down.

Reach is measured on the floor plane: the object must lie within ``pick_radius`` of the target
point (where the robot believes it is) and within ``arm_reach`` of the robot. A carried object
is not drawn and not detected; it rides on the robot until placed. A place target must be within
the arm's reach and inside the house; the object lands on whatever surface is there.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from merlin2_sailor_demos.world.geometry import Pose2D
from merlin2_sailor_demos.world.house import House
from merlin2_sailor_demos.world.objects import WorldObject
from merlin2_sailor_demos.world.yaml_fields import Fields


@dataclass(frozen=True, slots=True)
class GripperConfig:
    """Distances in metres: ``place_distance`` is how far ahead an object goes when no target is given,
    ``carry_height`` the height of a carried object's centre above the floor."""

    pick_radius: float = 0.6
    arm_reach: float = 1.5
    place_distance: float = 0.5
    carry_height: float = 0.6

    FIELDS = ("pick_radius", "arm_reach", "place_distance", "carry_height")

    @classmethod
    def from_mapping(cls, data: Any, where: str) -> GripperConfig:
        fields = Fields(data, where, cls.FIELDS)
        defaults = cls()
        return cls(**{name: fields.number(name, getattr(defaults, name), minimum=0.0, maximum=5.0)
                      for name in cls.FIELDS})


@dataclass(frozen=True, slots=True)
class GraspResult:
    success: bool
    message: str
    object_id: str = ""


class Gripper:
    def __init__(self, config: GripperConfig) -> None:
        self.config = config
        self.held: WorldObject | None = None

    def pick(self, objects: Sequence[WorldObject], class_name: str, target: Sequence[float],
             robot: Pose2D) -> GraspResult:
        """Take the object of ``class_name`` ('' for any) nearest ``target`` (x, y[, z]), if within reach."""
        if self.held is not None:
            return GraspResult(False, f"the gripper already holds '{self.held.id}'; place it first")
        if not all(math.isfinite(value) for value in target[:2]):
            return GraspResult(False, f"pick target {list(target)} is not a finite point")
        candidates = [item for item in objects
                      if not item.carried and (not class_name or item.class_name == class_name)]
        what = f"'{class_name}'" if class_name else "object"
        if not candidates:
            return GraspResult(False, f"there is no {what} in the world")
        distances = [math.dist(item.position[:2], target[:2]) for item in candidates]
        nearest = int(np.argmin(distances))
        item = candidates[nearest]
        if distances[nearest] > self.config.pick_radius:
            return GraspResult(False, f"no {what} within {self.config.pick_radius:g} m of ({target[0]:.2f}, "
                                      f"{target[1]:.2f}); the nearest is {distances[nearest]:.2f} m away")
        reach = robot.distance_to(*item.position[:2])
        if reach > self.config.arm_reach:
            return GraspResult(False, f"'{item.id}' is {reach:.2f} m from the robot, beyond the arm's reach of "
                                      f"{self.config.arm_reach:g} m; drive closer")
        item.carried = True
        self.held = item
        self.follow(robot)
        return GraspResult(True, f"picked '{item.id}'", item.id)

    def place(self, house: House, target: Sequence[float] | None, robot: Pose2D) -> GraspResult:
        """Put the held object at ``target`` (x, y[, z]), or ahead of the robot when None or not finite."""
        item = self.held
        if item is None:
            return GraspResult(False, "the gripper is empty")
        if target is None or not all(math.isfinite(value) for value in target[:2]):
            ahead = robot.compose(self.config.place_distance, 0.0, 0.0)
            x, y = ahead.x, ahead.y
        else:
            x, y = float(target[0]), float(target[1])
        reach = robot.distance_to(x, y)
        if reach > self.config.arm_reach:
            return GraspResult(False, f"({x:.2f}, {y:.2f}) is {reach:.2f} m from the robot, beyond the arm's "
                                      f"reach of {self.config.arm_reach:g} m", item.id)
        if house.room_at(x, y) is None:
            return GraspResult(False, f"({x:.2f}, {y:.2f}) is outside the house", item.id)
        item.position = np.array([x, y, house.support_height(x, y) + item.size[2] / 2.0])
        item.carried = False
        self.held = None
        return GraspResult(True, f"placed '{item.id}' at ({x:.2f}, {y:.2f}, {item.position[2]:.2f})", item.id)

    def follow(self, robot: Pose2D) -> None:
        """Keep the held object with the robot."""
        if self.held is not None:
            self.held.position = np.array([robot.x, robot.y, self.config.carry_height])
