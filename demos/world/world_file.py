"""A world file: the house, the object textures and objects, the robot, its camera, the scenario.

One YAML file (``config/worlds/house.yaml`` is the example) with the sections ``house``,
``textures``, ``objects``, and optionally ``robot``, ``camera``, ``depth_sensor``, ``scenario``,
a one-line ``description`` and the demo's ``mission`` (:mod:`.mission`). A file may instead
``extends`` another and list only its differences (:mod:`.world_extension`: the scenarios of
``config/worlds/scenarios/``). Loading checks the sections against each other (object ids unique,
every object in a room, every scenario event about an object that exists by then, every name the
mission uses) and says where a mistake is.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor_demos.world.camera import CameraConfig
from merlin2_sailor_demos.world.depth_sensor import DepthSensorConfig
from merlin2_sailor_demos.world.geometry import Pose2D
from merlin2_sailor_demos.world.gripper import GripperConfig
from merlin2_sailor_demos.world.house import House
from merlin2_sailor_demos.world.mission import MissionSpec
from merlin2_sailor_demos.world.motion import MotionLimits, limits_from_mapping
from merlin2_sailor_demos.world.objects import ObjectSpec
from merlin2_sailor_demos.world.odometry import OdometryNoise
from merlin2_sailor_demos.world.scenario import ScenarioEvent
from merlin2_sailor_demos.world.textures import TextureSpec
from merlin2_sailor_demos.world.world_extension import EXTENDS, REMOVE_OBJECTS, read_world_mapping
from merlin2_sailor_demos.world.yaml_fields import Fields

SECTIONS = ("house", "textures", "objects", "robot", "camera", "depth_sensor", "scenario", "description", "mission")


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
    description: str = ""
    mission: MissionSpec | None = None
    """The file's ``mission`` section; None when it has none (the demo then runs MissionSpec())."""

    @classmethod
    def from_mapping(cls, data: Any, where: str = "world") -> WorldDescription:
        if isinstance(data, Mapping) and (EXTENDS in data or REMOVE_OBJECTS in data):
            raise ConfigurationError(f"{where}: '{EXTENDS}' and '{REMOVE_OBJECTS}' work in a world file "
                                     "(load_world resolves them against the file's folder), not in a mapping")
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
            scenario, where, fields.text("description", ""),
            MissionSpec.from_mapping(fields.raw("mission"), f"{where}: mission") if fields.has("mission") else None,
        )
        _check_consistency(description, where)
        return description


def load_world(path: str | Path) -> WorldDescription:
    """Read and check a world file (its ``extends`` resolved); every problem is one
    ConfigurationError naming the file."""
    path = Path(path)
    return WorldDescription.from_mapping(read_world_mapping(path), path.name)


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
    names = [event.name for event in description.scenario]
    repeated = sorted({name for name in names if names.count(name) > 1})
    if repeated:
        raise ConfigurationError(f"{where}: scenario event names must be unique; repeated: {repeated}")
    for event in description.scenario:
        about = f"{where}: scenario event '{event.name}'"
        unknown_rooms = sorted(set(event.trigger.robot_in + event.trigger.robot_not_in) - rooms)
        if unknown_rooms:
            raise ConfigurationError(f"{about}: unknown room(s) {unknown_rooms}; rooms: {sorted(rooms)}")
        unknown_waypoints = sorted(set(event.trigger.after_visiting) - waypoints)
        if unknown_waypoints:
            raise ConfigurationError(
                f"{about}: unknown waypoint(s) {unknown_waypoints}; waypoints: {sorted(waypoints)}")
        if event.trigger.after_event is not None and event.trigger.after_event not in set(names) - {event.name}:
            raise ConfigurationError(f"{about}: after_event names '{event.trigger.after_event}', not another "
                                     f"event of this file (events: {sorted(names)})")
        if event.action == "add":
            if event.object_id in ids:
                raise ConfigurationError(f"{about}: adds '{event.object_id}', which already exists")
            ids.add(event.object_id)
        elif event.object_id not in ids:
            raise ConfigurationError(f"{about}: no object '{event.object_id}' (objects: {sorted(ids)})")
        if event.destination is not None and house.room_at(*event.destination) is None:
            raise ConfigurationError(f"{about}: destination {event.destination} is in no room")
    if description.mission is not None:
        initial = {spec.id for spec in description.objects}
        description.mission.check(initial, ids - initial, waypoints, {event.name for event in description.scenario},
                                  f"{where}: mission")
