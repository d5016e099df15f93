"""A world file: the house, the object textures and objects, the robot, its camera, the scenario.

One YAML file (``config/worlds/house.yaml`` is the example) with the sections ``house``,
``textures``, ``objects``, and optionally ``robot``, ``camera``, ``depth_sensor`` and
``scenario``. Loading checks the sections against each other (object ids unique, every object in
a room, every scenario event about an object that exists by then) and says where a mistake is.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor_demos.world.camera import CameraConfig
from merlin2_sailor_demos.world.depth_sensor import DepthSensorConfig
from merlin2_sailor_demos.world.geometry import Pose2D
from merlin2_sailor_demos.world.gripper import GripperConfig
from merlin2_sailor_demos.world.house import House
from merlin2_sailor_demos.world.motion import MotionLimits, limits_from_mapping
from merlin2_sailor_demos.world.objects import ObjectSpec
from merlin2_sailor_demos.world.odometry import OdometryNoise
from merlin2_sailor_demos.world.scenario import ScenarioEvent
from merlin2_sailor_demos.world.textures import TextureSpec
from merlin2_sailor_demos.world.yaml_fields import Fields

SECTIONS = ("house", "textures", "objects", "robot", "camera", "depth_sensor", "scenario")


@dataclass(frozen=True)
class RobotConfig:
    """The robot's start pose, body radius (m, the clearance paths keep), motion, odometry and gripper."""

    start: Pose2D
    radius: float = 0.25
    limits: MotionLimits = field(default_factory=MotionLimits)
    odometry: OdometryNoise = field(default_factory=OdometryNoise)
    gripper: GripperConfig = field(default_factory=GripperConfig)

    @classmethod
    def from_mapping(cls, data: Any, where: str, house: House) -> RobotConfig:
        fields = Fields(data or {}, where, ("start", "radius", "motion", "odometry", "gripper"))
        start = fields.raw("start", house.waypoints[0].name if house.waypoints else [0.0, 0.0, 0.0])
        if isinstance(start, str):
            pose = house.waypoint(start).pose
        else:
            x, y, yaw = fields.vector("start", 3)
            pose = Pose2D(x, y, yaw)
        if house.room_at(pose.x, pose.y) is None:
            raise ConfigurationError(f"{where}: the start ({pose.x}, {pose.y}) is in no room")
        return cls(
            pose, fields.number("radius", 0.25, minimum=0.05, maximum=1.0),
            limits_from_mapping(fields.raw("motion", {}), f"{where}.motion"),
            OdometryNoise.from_mapping(fields.raw("odometry", {}), f"{where}.odometry"),
            GripperConfig.from_mapping(fields.raw("gripper", {}), f"{where}.gripper"),
        )


@dataclass(frozen=True)
class WorldDescription:
    house: House
    textures: Mapping[str, TextureSpec]
    objects: tuple[ObjectSpec, ...]
    robot: RobotConfig
    camera: CameraConfig = field(default_factory=CameraConfig)
    depth_sensor: DepthSensorConfig = field(default_factory=DepthSensorConfig)
    scenario: tuple[ScenarioEvent, ...] = ()
    source: str = ""

    @classmethod
    def from_mapping(cls, data: Any, where: str = "world") -> WorldDescription:
        fields = Fields(data, where, SECTIONS)
        house = House.from_mapping(fields.raw("house"), f"{where}: house")
        texture_data = fields.raw("textures")
        if not isinstance(texture_data, Mapping) or not texture_data:
            raise ConfigurationError(f"{where}: 'textures' must map texture names to photo descriptions")
        textures = {str(name): TextureSpec.from_mapping(spec, f"{where}: textures.{name}")
                    for name, spec in texture_data.items()}
        names = set(textures)
        objects = tuple(ObjectSpec.from_mapping(item, f"{where}: objects[{index}]", names)
                        for index, item in enumerate(fields.sequence("objects")))
        robot = RobotConfig.from_mapping(fields.raw("robot", {}), f"{where}: robot", house)
        scenario = tuple(ScenarioEvent.from_mapping(item, f"{where}: scenario[{index}]", names)
                         for index, item in enumerate(fields.sequence("scenario", [])))
        description = cls(
            house, textures, objects, robot,
            CameraConfig.from_mapping(fields.raw("camera", {}), f"{where}: camera"),
            DepthSensorConfig.from_mapping(fields.raw("depth_sensor", {}), f"{where}: depth_sensor"),
            scenario, where,
        )
        _check_consistency(description, where)
        return description


def load_world(path: str | Path) -> WorldDescription:
    """Read and check a world file; every problem is one ConfigurationError naming the file."""
    path = Path(path)
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except OSError as error:
        raise ConfigurationError(f"cannot read world file {path}: {error.strerror or error}") from error
    except yaml.YAMLError as error:
        raise ConfigurationError(f"world file {path} is not valid YAML: {error}") from error
    return WorldDescription.from_mapping(data, path.name)


def _check_consistency(description: WorldDescription, where: str) -> None:
    house = description.house
    ids: set[str] = set()
    for spec in description.objects:
        if spec.id in ids:
            raise ConfigurationError(f"{where}: object id '{spec.id}' is used twice")
        ids.add(spec.id)
        if house.room_at(*spec.xy) is None:
            raise ConfigurationError(f"{where}: object '{spec.id}' at {spec.xy} is in no room")
    rooms = {room.name for room in house.rooms}
    waypoints = {waypoint.name for waypoint in house.waypoints}
    for event in description.scenario:
        about = f"{where}: scenario event '{event.name}'"
        unknown_rooms = sorted(set(event.trigger.robot_in + event.trigger.robot_not_in) - rooms)
        if unknown_rooms:
            raise ConfigurationError(f"{about}: unknown room(s) {unknown_rooms}; rooms: {sorted(rooms)}")
        unknown_waypoints = sorted(set(event.trigger.after_visiting) - waypoints)
        if unknown_waypoints:
            raise ConfigurationError(
                f"{about}: unknown waypoint(s) {unknown_waypoints}; waypoints: {sorted(waypoints)}")
        if event.action == "add":
            if event.object_id in ids:
                raise ConfigurationError(f"{about}: adds '{event.object_id}', which already exists")
            ids.add(event.object_id)
        elif event.object_id not in ids:
            raise ConfigurationError(f"{about}: no object '{event.object_id}' (objects: {sorted(ids)})")
        if event.destination is not None and house.room_at(*event.destination) is None:
            raise ConfigurationError(f"{about}: destination {event.destination} is in no room")
