"""Random houses for the simulated world: rooms, furniture, photo-textured objects, look-alikes.

The matching network must learn what the robot's camera really produces in a house: crops with
the table or the wall behind the object, objects cut by the image's edge or hidden in part by a
door frame, sizes measured from depth that change with the viewpoint, centres of a television or
a bicycle that move with the part in view. So it is trained on tours of houses rendered by the
same renderer the demo uses (:mod:`.house_source`), and those houses come from here. None is the
demo's house: layouts, furniture, objects, classes, sizes and photo assignments are all drawn.

A house is a grid of 2 to 6 rooms (one or two rows), joined by doorways along a random spanning
tree of the grid plus a few extra doors, each with a waypoint near its middle facing a random
way. Furniture stands against the walls, clear of the doorways. Objects stand on furniture or
on the floor near a wall, of COCO classes with sizes typical of the class, textured with a
region of one of the photos that ship in packages (:mod:`merlin2_sailor_demos.world.photos`). What
makes identity hard is drawn on purpose:

- families: objects of a class already in the house often take a relative's photo with another
  crop, colour, border or mirror (the red, blue and green mugs of the demo are one such family);
- twins: an object may copy a relative's texture exactly (only position and history tell them
  apart);
- rows: a furniture top may hold a row of three or four objects of one class, 0.2 to 0.35 m apart
  (books on a shelf);
- large objects (televisions, bicycles, chairs, suitcases), seen in part from most places;
- moves: an object may be moved to another place while the robot looks elsewhere;
- swaps: two objects of one class that look different may exchange places while the robot looks
  elsewhere, so that a place seen before shows another object of the anchor's class there: only
  appearance tells that it is not the anchor's object (without swaps, "same class, same place"
  always meant "same object" in training, and the network learnt to ignore colour there).

:func:`generate_house` returns the mapping of a world file, read by
:meth:`~merlin2_sailor_demos.world.world_file.WorldDescription.from_mapping` like any other.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from merlin2_sailor.errors import ConfigurationError, DependencyError
from merlin2_sailor_demos.world.photos import load_photo
from merlin2_sailor_demos.world.world_file import WorldDescription


@dataclass(frozen=True, slots=True)
class ObjectClass:
    """A COCO class and the sizes (x, y, height; metres) its objects are drawn between; ``floor``:
    where it stands (True: the floor, False: furniture, None: either); ``turn``: its footprint may
    be turned by 90 degrees."""

    name: str
    smallest: tuple[float, float, float]
    largest: tuple[float, float, float]
    floor: bool | None = False
    turn: bool = True


#: The classes of generated houses: everyday objects, small and large.
OBJECT_CLASSES = (
    ObjectClass("cup", (0.08, 0.08, 0.09), (0.12, 0.12, 0.13)),
    ObjectClass("bottle", (0.06, 0.06, 0.2), (0.1, 0.1, 0.32)),
    ObjectClass("bowl", (0.14, 0.14, 0.06), (0.22, 0.22, 0.1)),
    ObjectClass("book", (0.03, 0.15, 0.2), (0.06, 0.24, 0.3)),
    ObjectClass("vase", (0.1, 0.1, 0.2), (0.18, 0.18, 0.4)),
    ObjectClass("clock", (0.05, 0.2, 0.2), (0.08, 0.32, 0.32)),
    ObjectClass("laptop", (0.25, 0.2, 0.15), (0.36, 0.28, 0.25)),
    ObjectClass("bird", (0.15, 0.12, 0.15), (0.3, 0.25, 0.32)),
    ObjectClass("teddy bear", (0.18, 0.15, 0.2), (0.35, 0.3, 0.4), None),
    ObjectClass("cat", (0.3, 0.2, 0.25), (0.5, 0.3, 0.35), None),
    ObjectClass("potted plant", (0.2, 0.2, 0.3), (0.4, 0.4, 0.7), None),
    ObjectClass("backpack", (0.15, 0.25, 0.35), (0.25, 0.35, 0.5), None),
    ObjectClass("dog", (0.4, 0.25, 0.4), (0.7, 0.35, 0.6), True),
    ObjectClass("tv", (0.08, 0.6, 0.4), (0.15, 1.1, 0.7)),
    ObjectClass("microwave", (0.3, 0.45, 0.25), (0.4, 0.55, 0.32)),
    ObjectClass("suitcase", (0.2, 0.4, 0.5), (0.3, 0.6, 0.75), True),
    ObjectClass("chair", (0.4, 0.4, 0.8), (0.5, 0.5, 1.0), True),
    ObjectClass("bicycle", (0.3, 1.3, 0.9), (0.4, 1.8, 1.1), True),
)

#: Classes whose objects are put in rows on a furniture top.
ROW_CLASSES = ("book", "cup", "bottle", "clock", "vase", "bowl")

#: Photos textures are cut from: scikit-image's bundled images and darknet's (when installed).
SKIMAGE_PHOTOS = ("astronaut", "brick", "camera", "cat", "cell", "chelsea", "clock", "coffee", "coins", "colorwheel",
                  "grass", "gravel", "hubble_deep_field", "immunohistochemistry", "logo", "moon", "page", "retina",
                  "rocket", "text")
DARKNET_PHOTOS = ("dog", "eagle", "giraffe", "horses", "kite", "person", "scream")

FURNITURE_KINDS = ("table", "shelf", "cabinet", "counter", "desk")
FURNITURE_MATERIALS = ("wood", "dark_wood", "fabric", "white", "metal")
FLOORS = ("wood", "tiles", "carpet")

#: The robot of the demo (config/worlds/house.yaml): the houses change, the robot and its camera do not.
ROBOT = {
    "radius": 0.25,
    "motion": {"max_linear_speed": 2.0, "max_linear_acceleration": 3.0, "max_angular_speed": 3.0,
               "max_angular_acceleration": 8.0, "position_tolerance": 0.03, "heading_tolerance": 0.03},
    "odometry": {"translation_noise": 0.005, "rotation_noise": 0.01, "heading_noise": 0.003, "scale_error": 0.005,
                 "heading_drift": 0.003, "localisation_position": 0.01, "localisation_heading": 0.005,
                 "localisation_period": 1.0},
}
CAMERA = {"width": 640, "height": 480, "fx": 525.0, "fy": 525.0, "cx": 319.5, "cy": 239.5, "mount_height": 1.0,
          "mount_forward": 0.1}
DEPTH_SENSOR = {"minimum_range": 0.3, "maximum_range": 6.0, "noise_base": 0.001, "noise_quadratic": 0.0015,
                "dropout": 0.002}

#: Clearances (m): of furniture and floor objects from doorway centres, of floor objects from a
#: room's waypoint (the robot turns there), and between two objects' footprints.
DOOR_CLEARANCE = 1.1
WAYPOINT_CLEARANCE = 1.3
OBJECT_GAP = 0.04


def _check_range(name: str, values: tuple[float, float], minimum: float) -> None:
    low, high = values
    if not (math.isfinite(low) and math.isfinite(high) and minimum <= low <= high):
        raise ConfigurationError(f"house generator {name} must be a range (low, high) with {minimum} <= low <= high, "
                                 f"got {values}.")


#: Two objects swapped stand at least this far apart (metres): nearer, the swap is a small move.
SWAP_SEPARATION = 0.5


@dataclass(frozen=True, slots=True)
class HouseGeneratorConfig:
    """How generated houses look (see the module docstring). Counts are (low, high) inclusive,
    sizes in metres; probabilities per object (``family``, ``twin``), per furniture top
    (``row``) and per house (``move``, for each of up to ``moves`` moves; ``swap``, for each of up
    to ``swaps`` swaps)."""

    columns: tuple[int, int] = (1, 3)
    rows: tuple[int, int] = (1, 2)
    room_width: tuple[float, float] = (3.0, 5.0)
    room_depth: tuple[float, float] = (3.0, 4.5)
    furniture_per_room: tuple[int, int] = (1, 3)
    objects_per_room: tuple[int, int] = (3, 7)
    family_probability: float = 0.5
    twin_probability: float = 0.3
    row_probability: float = 0.3
    moves: int = 2
    move_probability: float = 0.5
    swaps: int = 2
    swap_probability: float = 0.6
    use_darknet: bool = True

    def __post_init__(self) -> None:
        _check_range("columns", self.columns, 1)
        _check_range("rows", self.rows, 1)
        _check_range("room_width", self.room_width, 2.5)
        _check_range("room_depth", self.room_depth, 2.5)
        _check_range("furniture_per_room", self.furniture_per_room, 0)
        _check_range("objects_per_room", self.objects_per_room, 0)
        if self.columns[1] * self.rows[1] < 2:
            raise ConfigurationError("house generator columns x rows must allow at least two rooms.")
        for name in ("family_probability", "twin_probability", "row_probability", "move_probability",
                     "swap_probability"):
            value = getattr(self, name)
            if not (0.0 <= value <= 1.0):
                raise ConfigurationError(f"house generator {name} must be a probability in [0, 1], got {value}.")
        if self.moves < 0 or self.swaps < 0:
            raise ConfigurationError(f"house generator moves and swaps must be >= 0, got {self.moves}, {self.swaps}.")


@dataclass(slots=True)
class _Room:
    name: str
    x_min: float
    y_min: float
    x_max: float
    y_max: float
    doors: list[tuple[float, float]] = field(default_factory=list)
    furniture: list[dict[str, Any]] = field(default_factory=list)
    waypoint: tuple[float, float] = (0.0, 0.0)


@dataclass(slots=True)
class _Placed:
    id: str
    class_name: str
    xy: np.ndarray
    size: np.ndarray
    texture: str
    room: str
    in_row: bool = False


class _HouseBuilder:
    def __init__(self, rng: np.random.Generator, config: HouseGeneratorConfig, photos: Sequence[str],
                 darknet_data: str | None) -> None:
        self.rng, self.config, self.photos, self.darknet_data = rng, config, tuple(photos), darknet_data
        self.rooms: list[_Room] = []
        self.doorways: list[dict[str, Any]] = []
        self.textures: dict[str, dict[str, Any]] = {}
        self.objects: list[_Placed] = []
        self.photo_sizes: dict[str, tuple[int, int]] = {}

    # --- layout ---------------------------------------------------------------------------------

    def layout(self) -> None:
        rng, config = self.rng, self.config
        while True:
            columns = int(rng.integers(config.columns[0], config.columns[1] + 1))
            rows = int(rng.integers(config.rows[0], config.rows[1] + 1))
            if columns * rows >= 2:
                break
        widths = np.round(rng.uniform(*config.room_width, size=columns), 1)
        depths = np.round(rng.uniform(*config.room_depth, size=rows), 1)
        xs, ys = np.concatenate(([0.0], np.cumsum(widths))), np.concatenate(([0.0], np.cumsum(depths)))
        grid = {}
        for row in range(rows):
            for column in range(columns):
                room = _Room(f"room_{row}_{column}", float(xs[column]), float(ys[row]), float(xs[column + 1]),
                             float(ys[row + 1]))
                grid[row, column] = room
                self.rooms.append(room)
        edges = [((r, c), (r, c + 1)) for r in range(rows) for c in range(columns - 1)]
        edges += [((r, c), (r + 1, c)) for r in range(rows - 1) for c in range(columns)]
        order = rng.permutation(len(edges))
        group = {cell: cell for cell in grid}

        def root(cell: tuple[int, int]) -> tuple[int, int]:
            while group[cell] != cell:
                cell = group[cell]
            return cell

        for index in order:  # a random spanning tree (Kruskal), plus each other edge now and then
            first, second = edges[index]
            joined = root(first) != root(second)
            if joined:
                group[root(first)] = root(second)
            if joined or rng.random() < 0.3:
                self._door(grid[first], grid[second])

    def _door(self, first: _Room, second: _Room) -> None:
        width = float(np.round(self.rng.uniform(0.9, 1.1), 2))
        if abs(first.x_max - second.x_min) < 1e-6:  # side by side: the wall runs along y
            low, high = max(first.y_min, second.y_min), min(first.y_max, second.y_max)
            x, y = first.x_max, float(np.round(self.rng.uniform(low + 0.8, high - 0.8), 2))
        else:
            low, high = max(first.x_min, second.x_min), min(first.x_max, second.x_max)
            x, y = float(np.round(self.rng.uniform(low + 0.8, high - 0.8), 2)), first.y_max
        self.doorways.append({"rooms": [first.name, second.name], "x": x, "y": y, "width": width})
        first.doors.append((x, y))
        second.doors.append((x, y))

    # --- furniture and waypoints ------------------------------------------------------------------

    def furnish(self) -> None:
        for room in self.rooms:
            count = int(self.rng.integers(self.config.furniture_per_room[0], self.config.furniture_per_room[1] + 1))
            for number in range(count):
                for _attempt in range(20):
                    piece = self._furniture_piece(room, number)
                    if piece is not None:
                        room.furniture.append(piece)
                        break
            cx, cy = (room.x_min + room.x_max) / 2.0, (room.y_min + room.y_max) / 2.0
            room.waypoint = (float(np.round(cx + self.rng.uniform(-0.3, 0.3), 2)),
                             float(np.round(cy + self.rng.uniform(-0.3, 0.3), 2)))

    def _furniture_piece(self, room: _Room, number: int) -> dict[str, Any] | None:
        rng = self.rng
        length, depth, height = rng.uniform(0.6, 1.6), rng.uniform(0.35, 0.8), rng.uniform(0.45, 1.0)
        side = int(rng.integers(4))
        along_x = side in (0, 1)  # against the south / north wall
        size = (length, depth) if along_x else (depth, length)
        if along_x:
            x = rng.uniform(room.x_min + size[0] / 2 + 0.05, room.x_max - size[0] / 2 - 0.05)
            y = room.y_min + size[1] / 2 + 0.02 if side == 0 else room.y_max - size[1] / 2 - 0.02
        else:
            y = rng.uniform(room.y_min + size[1] / 2 + 0.05, room.y_max - size[1] / 2 - 0.05)
            x = room.x_min + size[0] / 2 + 0.02 if side == 2 else room.x_max - size[0] / 2 - 0.02
        box = (x - size[0] / 2, y - size[1] / 2, x + size[0] / 2, y + size[1] / 2)
        if any(_box_distance(box, door) < DOOR_CLEARANCE for door in room.doors):
            return None
        for other in room.furniture:
            ox, oy = other["center"]
            osx, osy = other["size"][:2]
            if abs(ox - x) < (osx + size[0]) / 2 + 0.2 and abs(oy - y) < (osy + size[1]) / 2 + 0.2:
                return None
        # the middle of the room stays free for the robot's look around
        if _box_distance(box, ((room.x_min + room.x_max) / 2, (room.y_min + room.y_max) / 2)) < 0.9:
            return None
        return {"name": f"{room.name}_{FURNITURE_KINDS[int(rng.integers(len(FURNITURE_KINDS)))]}_{number}",
                "kind": FURNITURE_KINDS[int(rng.integers(len(FURNITURE_KINDS)))],
                "center": [float(np.round(x, 3)), float(np.round(y, 3))],
                "size": [float(np.round(size[0], 3)), float(np.round(size[1], 3)), float(np.round(height, 3))],
                "material": FURNITURE_MATERIALS[int(rng.integers(len(FURNITURE_MATERIALS)))]}

    # --- objects and textures ---------------------------------------------------------------------

    def populate(self) -> None:
        rng = self.rng
        for room in self.rooms:
            count = int(rng.integers(self.config.objects_per_room[0], self.config.objects_per_room[1] + 1))
            placed = 0
            for piece in room.furniture:
                if placed < count and rng.random() < self.config.row_probability:
                    placed += self._row(room, piece)
            attempts = 0
            while placed < count and attempts < 60:
                attempts += 1
                if self._single(room) is not None:
                    placed += 1

    def _row(self, room: _Room, piece: dict[str, Any]) -> int:
        rng = self.rng
        kind = _class_named(ROW_CLASSES[int(rng.integers(len(ROW_CLASSES)))])
        size = _draw_size(rng, kind)
        along_x = piece["size"][0] >= piece["size"][1]
        if along_x and size[0] > size[1] or not along_x and size[1] > size[0]:
            size = size[[1, 0, 2]]  # thin side along the row, as books stand on a shelf
        members = int(rng.integers(3, 5))
        spacing = rng.uniform(0.2, 0.35)
        span = spacing * (members - 1)
        length = piece["size"][0] if along_x else piece["size"][1]
        if span + 0.1 > length:
            return 0
        cx, cy = piece["center"]
        start = -span / 2 + rng.uniform(-(length - span - 0.1) / 2, (length - span - 0.1) / 2)
        texture = None
        count = 0
        for member in range(members):
            offset = start + member * spacing
            xy = np.array([cx + offset, cy] if along_x else [cx, cy + offset])
            member_size = size * rng.uniform(0.97, 1.03, size=3)
            if not self._fits(xy, member_size):
                continue
            texture = self._texture(kind.name, relative=texture)
            self._add(kind.name, xy, member_size, texture, room, in_row=True)
            count += 1
        return count

    def _single(self, room: _Room) -> _Placed | None:
        rng = self.rng
        existing = sorted({placed.class_name for placed in self.objects})
        if existing and rng.random() < self.config.family_probability:
            kind = _class_named(existing[int(rng.integers(len(existing)))])
        else:
            kind = OBJECT_CLASSES[int(rng.integers(len(OBJECT_CLASSES)))]
        size = _draw_size(rng, kind)
        on_floor = kind.floor if kind.floor is not None else bool(rng.random() < 0.5)
        tops = [piece for piece in room.furniture
                if piece["size"][0] > size[0] + 0.05 and piece["size"][1] > size[1] + 0.05]
        if not on_floor and tops:
            piece = tops[int(rng.integers(len(tops)))]
            (cx, cy), (sx, sy, _) = piece["center"], piece["size"]
            xy = np.array([cx + rng.uniform(-(sx - size[0]) / 2, (sx - size[0]) / 2),
                           cy + rng.uniform(-(sy - size[1]) / 2, (sy - size[1]) / 2)])
        else:
            xy = self._floor_spot(room, size)
            if xy is None:
                return None
        if not self._fits(xy, size):
            return None
        relatives = [placed for placed in self.objects if placed.class_name == kind.name]
        draw = rng.random()
        if relatives and draw < self.config.twin_probability:
            twin = relatives[int(rng.integers(len(relatives)))]
            twin_size = twin.size * rng.uniform(0.97, 1.03, size=3)
            if not self._fits(xy, twin_size) or not self._on_support(room, xy, twin_size, on_floor or not tops):
                return None
            return self._add(kind.name, xy, twin_size, twin.texture, room)
        relative = None
        if relatives and draw < self.config.twin_probability + self.config.family_probability:
            relative = relatives[int(rng.integers(len(relatives)))].texture
        return self._add(kind.name, xy, size, self._texture(kind.name, relative), room)

    def _on_support(self, room: _Room, xy: np.ndarray, size: np.ndarray, on_floor: bool) -> bool:
        """Whether an object of ``size`` at ``xy`` stands wholly on one furniture top (or, on the
        floor, clear of every piece)."""
        for piece in room.furniture:
            (cx, cy), (sx, sy, _) = piece["center"], piece["size"]
            inside = abs(cx - xy[0]) <= (sx - size[0]) / 2 and abs(cy - xy[1]) <= (sy - size[1]) / 2
            touching = abs(cx - xy[0]) < (sx + size[0]) / 2 and abs(cy - xy[1]) < (sy + size[1]) / 2
            if not on_floor and inside:
                return True
            if on_floor and touching:
                return False
        return on_floor

    def _floor_spot(self, room: _Room, size: np.ndarray) -> np.ndarray | None:
        rng = self.rng
        side = int(rng.integers(4))
        gap = rng.uniform(0.05, 0.4)
        if side in (0, 1):
            x = rng.uniform(room.x_min + 0.4, room.x_max - 0.4)
            y = room.y_min + size[1] / 2 + gap if side == 0 else room.y_max - size[1] / 2 - gap
        else:
            y = rng.uniform(room.y_min + 0.4, room.y_max - 0.4)
            x = room.x_min + size[0] / 2 + gap if side == 2 else room.x_max - size[0] / 2 - gap
        xy = np.array([x, y])
        box = (x - size[0] / 2, y - size[1] / 2, x + size[0] / 2, y + size[1] / 2)
        if any(_box_distance(box, door) < DOOR_CLEARANCE for door in room.doors):
            return None
        if _box_distance(box, room.waypoint) < WAYPOINT_CLEARANCE:
            return None
        for piece in room.furniture:  # not half on a piece of furniture
            (cx, cy), (sx, sy, _) = piece["center"], piece["size"]
            if abs(cx - x) < (sx + size[0]) / 2 + 0.05 and abs(cy - y) < (sy + size[1]) / 2 + 0.05:
                return None
        return xy

    def _fits(self, xy: np.ndarray, size: np.ndarray) -> bool:
        for other in self.objects:
            if np.all(np.abs(other.xy - xy) < (other.size[:2] + size[:2]) / 2 + OBJECT_GAP):
                return False
        return True

    def _add(self, class_name: str, xy: np.ndarray, size: np.ndarray, texture: str, room: _Room,
             in_row: bool = False) -> _Placed:
        placed = _Placed(f"object_{len(self.objects)}", class_name, xy, np.asarray(size, dtype=np.float64), texture,
                         room.name, in_row)
        self.objects.append(placed)
        return placed

    def _texture(self, class_name: str, relative: str | None = None) -> str:
        """A new texture; with a ``relative``, from its photo (and crop, half the time), changed."""
        rng = self.rng
        name = f"texture_{len(self.textures)}"
        if relative is not None:
            spec = dict(self.textures[relative])
            if rng.random() < 0.5:
                spec["crop"] = self._crop(spec["photo"])
            change = int(rng.integers(3))
            if change == 0:
                spec["recolor"] = _colour(rng)
            elif change == 1:
                spec["border"] = _colour(rng)
                spec["border_fraction"] = float(np.round(rng.uniform(0.05, 0.15), 3))
            else:
                spec["mirror"] = not spec.get("mirror", False)
        else:
            photo = self.photos[int(rng.integers(len(self.photos)))]
            spec = {"photo": photo, "crop": self._crop(photo)}
            if rng.random() < 0.25:
                spec["recolor"] = _colour(rng)
            if rng.random() < 0.3:
                spec["border"] = _colour(rng)
                spec["border_fraction"] = float(np.round(rng.uniform(0.04, 0.14), 3))
            if rng.random() < 0.2:
                spec["mirror"] = True
        self.textures[name] = spec
        return name

    def _crop(self, photo: str) -> list[int]:
        if photo not in self.photo_sizes:
            self.photo_sizes[photo] = load_photo(photo, self.darknet_data).shape[:2]
        height, width = self.photo_sizes[photo]
        crop_width, crop_height = width * self.rng.uniform(0.3, 0.9), height * self.rng.uniform(0.3, 0.9)
        x0, y0 = self.rng.uniform(0, width - crop_width), self.rng.uniform(0, height - crop_height)
        return [int(x0), int(y0), int(x0 + crop_width), int(y0 + crop_height)]

    # --- the whole ----------------------------------------------------------------------------------

    def scenario(self, stops: int) -> list[dict[str, Any]]:
        rng = self.rng
        events = []
        movable = [placed for placed in self.objects if not placed.in_row]
        for number in range(self.config.moves):
            if not movable or rng.random() >= self.config.move_probability:
                continue
            placed = movable.pop(int(rng.integers(len(movable))))
            room, xy = None, None
            for _attempt in range(20):  # a free spot by a wall of some room
                room = self.rooms[int(rng.integers(len(self.rooms)))]
                xy = self._floor_spot(room, placed.size)
                if xy is not None and self._fits(xy, placed.size):
                    break
                xy = None
            if room is None or xy is None:
                continue
            events.append({"name": f"move_{number}",
                           "when": {"after_arrivals": int(rng.integers(1, max(stops, 2))),
                                    "robot_not_in": sorted({placed.room, room.name})},
                           "move": {"object": placed.id, "to": [float(np.round(v, 3)) for v in xy]}})
        for number in range(self.config.swaps):
            if rng.random() >= self.config.swap_probability:
                continue
            pairs = [(a, b) for k, a in enumerate(movable) for b in movable[k + 1:]
                     if a.class_name == b.class_name and a.texture != b.texture
                     and float(np.linalg.norm(a.xy - b.xy)) > SWAP_SEPARATION]
            if not pairs:
                continue
            first, second = pairs[int(rng.integers(len(pairs)))]
            movable = [placed for placed in movable if placed is not first and placed is not second]
            when = {"after_arrivals": int(rng.integers(1, max(stops, 2))),
                    "robot_not_in": sorted({first.room, second.room})}
            for suffix, placed, other in (("a", first, second), ("b", second, first)):
                events.append({"name": f"swap_{number}_{suffix}", "when": dict(when),
                               "move": {"object": placed.id, "to": [float(np.round(v, 3)) for v in other.xy]}})
        return events

    def mapping(self) -> dict[str, Any]:
        rng = self.rng
        rooms = [{"name": room.name, "x_min": room.x_min, "y_min": room.y_min, "x_max": room.x_max,
                  "y_max": room.y_max, "floor": FLOORS[int(rng.integers(len(FLOORS)))],
                  "wall_color": [int(v) for v in rng.integers(180, 245, size=3)]} for room in self.rooms]
        waypoints = [{"name": room.name, "x": room.waypoint[0], "y": room.waypoint[1],
                      "yaw": float(np.round(rng.uniform(-math.pi, math.pi), 3))} for room in self.rooms]
        objects = [{"id": placed.id, "class": placed.class_name,
                    "position": [float(np.round(v, 3)) for v in placed.xy],
                    "size": [float(np.round(v, 3)) for v in placed.size], "texture": placed.texture}
                   for placed in self.objects]
        return {
            "description": "a generated house (merlin2_sailor_demos.identity.generated_houses)",
            "house": {"wall_height": 2.5, "rooms": rooms, "doorways": self.doorways,
                      "furniture": [piece for room in self.rooms for piece in room.furniture],
                      "waypoints": waypoints},
            "textures": self.textures,
            "objects": objects,
            "robot": {"start": self.rooms[0].name, **ROBOT},
            "camera": CAMERA,
            "depth_sensor": DEPTH_SENSOR,
            "scenario": self.scenario(len(self.rooms)),
        }


def available_photos(use_darknet: bool = True, darknet_data: str | None = None) -> list[str]:
    """The photo names textures use: scikit-image's and, with ``use_darknet``, darknet's.

    Every one must load: a missing photo would silently make other houses (and another data set)
    from the same seed, so it is an error that says what to install.
    """
    names = [f"skimage/{name}" for name in SKIMAGE_PHOTOS]
    if use_darknet:
        names += [f"darknet/{name}" for name in DARKNET_PHOTOS]
    for name in names:
        try:
            load_photo(name, darknet_data)
        except DependencyError as error:
            raise DependencyError(
                f"generated houses need photo {name}: {error}. Without darknet's photos, generate with "
                "use_darknet=False (`--no-darknet`): other houses, another data set."
            ) from error
    return names


def generate_house(rng: np.random.Generator, config: HouseGeneratorConfig | None = None,
                   photos: Sequence[str] | None = None, darknet_data: str | None = None) -> dict[str, Any]:
    """The world-file mapping of one random house (see the module docstring); ``photos``: the
    photo names textures may use (default :func:`available_photos`)."""
    config = config or HouseGeneratorConfig()
    if photos is None:
        photos = available_photos(config.use_darknet, darknet_data)
    builder = _HouseBuilder(rng, config, photos, darknet_data)
    builder.layout()
    builder.furnish()
    builder.populate()
    return builder.mapping()


def generated_world(rng: np.random.Generator, config: HouseGeneratorConfig | None = None,
                    photos: Sequence[str] | None = None, darknet_data: str | None = None) -> WorldDescription:
    """:func:`generate_house`, read as a world file."""
    return WorldDescription.from_mapping(generate_house(rng, config, photos, darknet_data), "generated house")


def twins_of(description: WorldDescription) -> set[str]:
    """Ids of objects that share their texture with another object of their class (true look-alikes)."""
    by_texture: dict[tuple[str, str], list[str]] = {}
    for spec in description.objects:
        by_texture.setdefault((spec.class_name, spec.texture), []).append(spec.id)
    return {object_id for ids in by_texture.values() if len(ids) > 1 for object_id in ids}


def _class_named(name: str) -> ObjectClass:
    for kind in OBJECT_CLASSES:
        if kind.name == name:
            return kind
    raise ConfigurationError(f"no generated object class named {name!r}")


def _draw_size(rng: np.random.Generator, kind: ObjectClass) -> np.ndarray:
    size = rng.uniform(kind.smallest, kind.largest)
    if kind.turn and rng.random() < 0.5:
        size = size[[1, 0, 2]]
    return size


def _colour(rng: np.random.Generator) -> list[int]:
    """A saturated colour: one channel high, one low, one anywhere."""
    channels = rng.permutation(3)
    colour = np.zeros(3, dtype=int)
    colour[channels[0]] = int(rng.integers(160, 235))
    colour[channels[1]] = int(rng.integers(15, 70))
    colour[channels[2]] = int(rng.integers(15, 235))
    return [int(v) for v in colour]


def _box_distance(box: tuple[float, float, float, float], point: tuple[float, float]) -> float:
    """Distance from a point to an (x0, y0, x1, y1) rectangle (0 inside)."""
    x0, y0, x1, y1 = box
    dx = max(x0 - point[0], 0.0, point[0] - x1)
    dy = max(y0 - point[1], 0.0, point[1] - y1)
    return math.hypot(dx, dy)
