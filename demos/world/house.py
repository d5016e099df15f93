"""The house: rooms, the doorways between them, the walls they imply, furniture and waypoints.

Rooms are axis-aligned rectangles that meet edge to edge. Walls are not written by hand: every
room edge is a wall, edges shared by two rooms become one wall, and each doorway cuts its gap out
of the wall it sits on. So a house file lists rooms and doors, and the walls can never disagree
with them. Furniture is a set of axis-aligned boxes standing on the floor; their tops are the
surfaces objects stand on.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor_demos.world.geometry import Box, Pose2D
from merlin2_sailor_demos.world.yaml_fields import Fields

#: Two coordinates closer than this (metres) are the same line, e.g. two rooms' shared edge.
COORDINATE_TOLERANCE = 1e-6
#: Wall pieces shorter than this (metres) left over between doorways are dropped.
MINIMUM_WALL_LENGTH = 0.01

FLOOR_MATERIALS = ("wood", "tiles", "carpet")
FURNITURE_MATERIALS = ("wood", "dark_wood", "fabric", "white", "metal")


@dataclass(frozen=True, slots=True)
class Room:
    """An axis-aligned rectangle of floor with its floor material and wall paint (RGB)."""

    name: str
    x_min: float
    y_min: float
    x_max: float
    y_max: float
    floor: str = "wood"
    wall_color: tuple[int, int, int] = (225, 220, 205)

    def contains(self, x: float, y: float, margin: float = 0.0) -> bool:
        return self.x_min - margin <= x <= self.x_max + margin and self.y_min - margin <= y <= self.y_max + margin

    @property
    def center(self) -> tuple[float, float]:
        return ((self.x_min + self.x_max) / 2.0, (self.y_min + self.y_max) / 2.0)


@dataclass(frozen=True, slots=True)
class Doorway:
    """A gap of ``width`` metres centred on (x, y), in the wall shared by ``rooms``.

    ``vertical`` is True when that wall runs along y (the doorway is crossed along x).
    """

    rooms: tuple[str, str]
    x: float
    y: float
    width: float
    vertical: bool

    @property
    def normal(self) -> np.ndarray:
        """Unit vector across the doorway."""
        return np.array([1.0, 0.0]) if self.vertical else np.array([0.0, 1.0])


@dataclass(frozen=True, slots=True)
class Wall:
    """A vertical wall between two floor points, axis-aligned, as tall as the house's walls."""

    start: tuple[float, float]
    end: tuple[float, float]

    @property
    def length(self) -> float:
        return math.dist(self.start, self.end)


@dataclass(frozen=True, slots=True)
class Furniture:
    """A piece of furniture: an axis-aligned box on the floor; ``kind`` is what it is (table, couch)."""

    name: str
    kind: str
    box: Box
    material: str = "wood"


@dataclass(frozen=True, slots=True)
class Waypoint:
    """A named pose the robot navigates to; its heading is the one it faces on arrival."""

    name: str
    pose: Pose2D


@dataclass(frozen=True)
class House:
    """Rooms, doorways, furniture and waypoints; ``walls`` are derived from rooms and doorways."""

    rooms: tuple[Room, ...]
    doorways: tuple[Doorway, ...] = ()
    furniture: tuple[Furniture, ...] = ()
    waypoints: tuple[Waypoint, ...] = ()
    wall_height: float = 2.5
    walls: tuple[Wall, ...] = field(init=False)

    def __post_init__(self) -> None:
        _check_house(self)
        object.__setattr__(self, "walls", derive_walls(self.rooms, self.doorways))

    # --- queries ---------------------------------------------------------------------------------

    def room(self, name: str) -> Room:
        for room in self.rooms:
            if room.name == name:
                return room
        raise ConfigurationError(f"no room named '{name}'; rooms: {[room.name for room in self.rooms]}")

    def room_at(self, x: float, y: float) -> Room | None:
        """The room containing (x, y); on a shared edge, the first listed."""
        for room in self.rooms:
            if room.contains(x, y):
                return room
        return None

    def waypoint(self, name: str) -> Waypoint:
        for waypoint in self.waypoints:
            if waypoint.name == name:
                return waypoint
        raise ConfigurationError(f"no waypoint named '{name}'; waypoints: {[w.name for w in self.waypoints]}")

    def support_height(self, x: float, y: float) -> float:
        """Height of the surface at (x, y): the top of the highest furniture there, else the floor (0)."""
        tops = [piece.box.top for piece in self.furniture if piece.box.contains_xy(x, y)]
        return max(tops, default=0.0)

    def furniture_at(self, x: float, y: float) -> Furniture | None:
        """The highest piece of furniture whose footprint holds (x, y)."""
        pieces = [piece for piece in self.furniture if piece.box.contains_xy(x, y)]
        return max(pieces, key=lambda piece: piece.box.top, default=None)

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """(x_min, y_min, x_max, y_max) of all rooms."""
        return (min(r.x_min for r in self.rooms), min(r.y_min for r in self.rooms),
                max(r.x_max for r in self.rooms), max(r.y_max for r in self.rooms))

    def wall_array(self) -> np.ndarray:
        """The walls as an (N, 4) array of (x0, y0, x1, y1)."""
        return np.array([[*wall.start, *wall.end] for wall in self.walls], dtype=np.float64).reshape(-1, 4)

    # --- YAML --------------------------------------------------------------------------------------

    @classmethod
    def from_mapping(cls, data: Any, where: str = "house") -> House:
        fields = Fields(data, where, ("wall_height", "rooms", "doorways", "furniture", "waypoints"))
        rooms = tuple(_room(item, f"{where}.rooms[{i}]") for i, item in enumerate(fields.sequence("rooms")))
        by_name = {room.name: room for room in rooms}
        doorways = tuple(_doorway(item, f"{where}.doorways[{i}]", by_name)
                         for i, item in enumerate(fields.sequence("doorways", [])))
        furniture = tuple(_furniture(item, f"{where}.furniture[{i}]")
                          for i, item in enumerate(fields.sequence("furniture", [])))
        waypoints = tuple(_waypoint(item, f"{where}.waypoints[{i}]")
                          for i, item in enumerate(fields.sequence("waypoints")))
        wall_height = fields.number("wall_height", 2.5, minimum=1.0, maximum=10.0)
        try:
            return cls(rooms, doorways, furniture, waypoints, wall_height)
        except ConfigurationError as error:
            raise ConfigurationError(f"{where}: {error}") from error


# --- walls ----------------------------------------------------------------------------------------


def derive_walls(rooms: Sequence[Room], doorways: Sequence[Doorway]) -> tuple[Wall, ...]:
    """Every room edge, merged where rooms share it, minus the doorways' gaps, and split at room
    corners so that each wall has one room (or the outside) on each side."""
    # (is the line vertical, its coordinate) -> intervals along the line
    lines: dict[tuple[bool, float], list[tuple[float, float]]] = {}
    for room in rooms:
        lines.setdefault((False, room.y_min), []).append((room.x_min, room.x_max))
        lines.setdefault((False, room.y_max), []).append((room.x_min, room.x_max))
        lines.setdefault((True, room.x_min), []).append((room.y_min, room.y_max))
        lines.setdefault((True, room.x_max), []).append((room.y_min, room.y_max))
    walls = []
    for (vertical, coordinate), intervals in sorted(lines.items()):
        gaps = [
            ((door.y if vertical else door.x) - door.width / 2.0, (door.y if vertical else door.x) + door.width / 2.0)
            for door in doorways
            if door.vertical == vertical and abs((door.x if vertical else door.y) - coordinate) < COORDINATE_TOLERANCE
        ]
        touching = [room for room in rooms if any(abs(edge - coordinate) < COORDINATE_TOLERANCE for edge in (
            (room.x_min, room.x_max) if vertical else (room.y_min, room.y_max)))]
        corners = sorted({value for room in touching
                          for value in ((room.y_min, room.y_max) if vertical else (room.x_min, room.x_max))})
        for low, high in _split(_subtract(_union(intervals), gaps), corners):
            if high - low < MINIMUM_WALL_LENGTH:
                continue
            if vertical:
                walls.append(Wall((coordinate, low), (coordinate, high)))
            else:
                walls.append(Wall((low, coordinate), (high, coordinate)))
    return tuple(walls)


def _union(intervals: list[tuple[float, float]]) -> list[tuple[float, float]]:
    merged: list[list[float]] = []
    for low, high in sorted(intervals):
        if merged and low <= merged[-1][1] + COORDINATE_TOLERANCE:
            merged[-1][1] = max(merged[-1][1], high)
        else:
            merged.append([low, high])
    return [(low, high) for low, high in merged]


def _split(intervals: list[tuple[float, float]], cuts: list[float]) -> list[tuple[float, float]]:
    pieces = []
    for low, high in intervals:
        inside = [cut for cut in cuts if low + COORDINATE_TOLERANCE < cut < high - COORDINATE_TOLERANCE]
        bounds = [low, *inside, high]
        pieces += list(zip(bounds, bounds[1:], strict=False))
    return pieces


def _subtract(intervals: list[tuple[float, float]], gaps: list[tuple[float, float]]) -> list[tuple[float, float]]:
    pieces = list(intervals)
    for gap_low, gap_high in gaps:
        next_pieces = []
        for low, high in pieces:
            if gap_high <= low or gap_low >= high:
                next_pieces.append((low, high))
                continue
            if gap_low > low:
                next_pieces.append((low, gap_low))
            if gap_high < high:
                next_pieces.append((gap_high, high))
        pieces = next_pieces
    return pieces


# --- validation and parsing -----------------------------------------------------------------------


def _check_house(house: House) -> None:
    if not house.rooms:
        raise ConfigurationError("a house needs at least one room")
    names = [room.name for room in house.rooms]
    if len(set(names)) != len(names):
        raise ConfigurationError(f"room names must be unique, got {names}")
    for index, room in enumerate(house.rooms):
        if not (room.x_min < room.x_max and room.y_min < room.y_max):
            raise ConfigurationError(f"room '{room.name}' needs x_min < x_max and y_min < y_max")
        for other in house.rooms[index + 1:]:
            overlap_x = min(room.x_max, other.x_max) - max(room.x_min, other.x_min)
            overlap_y = min(room.y_max, other.y_max) - max(room.y_min, other.y_min)
            if overlap_x > COORDINATE_TOLERANCE and overlap_y > COORDINATE_TOLERANCE:
                raise ConfigurationError(f"rooms '{room.name}' and '{other.name}' overlap")
    for piece in house.furniture:
        if not any(room.contains(*piece.box.center[:2]) for room in house.rooms):
            raise ConfigurationError(f"furniture '{piece.name}' at {piece.box.center[:2]} is in no room")
    waypoint_names = [waypoint.name for waypoint in house.waypoints]
    if len(set(waypoint_names)) != len(waypoint_names):
        raise ConfigurationError(f"waypoint names must be unique, got {waypoint_names}")
    for waypoint in house.waypoints:
        if not any(room.contains(waypoint.pose.x, waypoint.pose.y) for room in house.rooms):
            raise ConfigurationError(
                f"waypoint '{waypoint.name}' at ({waypoint.pose.x}, {waypoint.pose.y}) is in no room")
        inside = [piece.name for piece in house.furniture if piece.box.contains_xy(waypoint.pose.x, waypoint.pose.y)]
        if inside:
            raise ConfigurationError(f"waypoint '{waypoint.name}' is inside furniture {inside}")


def _room(data: Any, where: str) -> Room:
    fields = Fields(data, where, ("name", "x_min", "y_min", "x_max", "y_max", "floor", "wall_color"))
    floor = fields.text("floor", "wood")
    if floor not in FLOOR_MATERIALS:
        raise fields.fail("floor", f"one of {list(FLOOR_MATERIALS)}")
    return Room(fields.text("name"), fields.number("x_min"), fields.number("y_min"), fields.number("x_max"),
                fields.number("y_max"), floor, fields.color("wall_color", (225, 220, 205)))


def _doorway(data: Any, where: str, rooms: Mapping[str, Room]) -> Doorway:
    fields = Fields(data, where, ("rooms", "x", "y", "width"))
    names = fields.names("rooms")
    if len(names) != 2 or any(name not in rooms for name in names):
        raise fields.fail("rooms", f"two of the rooms {sorted(rooms)}")
    x, y, width = fields.number("x"), fields.number("y"), fields.number("width", 0.9, minimum=0.5, maximum=5.0)
    first, second = rooms[names[0]], rooms[names[1]]
    for vertical in (True, False):
        line = _shared_line(first, second, vertical)
        if line is None:
            continue
        coordinate, low, high = line
        along, across = (y, x) if vertical else (x, y)
        on_line = abs(across - coordinate) < COORDINATE_TOLERANCE
        if on_line and low <= along - width / 2.0 and along + width / 2.0 <= high:
            return Doorway((names[0], names[1]), x, y, width, vertical)
    raise ConfigurationError(
        f"{where}: a doorway of width {width} at ({x}, {y}) does not fit on the wall shared by '{names[0]}' and "
        f"'{names[1]}'; put it on their common edge, at least half its width from the edge's ends"
    )


def _shared_line(first: Room, second: Room, vertical: bool) -> tuple[float, float, float] | None:
    """(coordinate, low, high) of the edge two rooms share along x (vertical) or y, if any."""
    if vertical:
        edges, other_edges = (first.x_max, first.x_min), (second.x_min, second.x_max)
        low, high = max(first.y_min, second.y_min), min(first.y_max, second.y_max)
    else:
        edges, other_edges = (first.y_max, first.y_min), (second.y_min, second.y_max)
        low, high = max(first.x_min, second.x_min), min(first.x_max, second.x_max)
    candidates = [c for c in edges if any(abs(c - other) < COORDINATE_TOLERANCE for other in other_edges)]
    if not candidates or high <= low:
        return None
    return candidates[0], low, high


def _furniture(data: Any, where: str) -> Furniture:
    fields = Fields(data, where, ("name", "kind", "center", "size", "material"))
    name = fields.text("name")
    x, y = fields.vector("center", 2)
    size = fields.vector("size", 3, positive=True)
    material = fields.text("material", "wood")
    if material not in FURNITURE_MATERIALS:
        raise fields.fail("material", f"one of {list(FURNITURE_MATERIALS)}")
    return Furniture(name, fields.text("kind", "furniture"), Box((x, y, size[2] / 2.0), size), material)


def _waypoint(data: Any, where: str) -> Waypoint:
    fields = Fields(data, where, ("name", "x", "y", "yaw"))
    return Waypoint(fields.text("name"), Pose2D(fields.number("x"), fields.number("y"), fields.number("yaw", 0.0)))
