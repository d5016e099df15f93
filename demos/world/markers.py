"""What RViz should draw of the world, as plain data: the node turns each item into a Marker.

Walls, furniture, the true object positions (with their ids as labels) and the waypoints (arrows
with their names). Kept free of message types so it is tested without ROS.
"""

from __future__ import annotations

import colorsys
import math
import zlib
from dataclasses import dataclass

from merlin2_sailor_demos.world.world import World

WALL_THICKNESS = 0.05
LABEL_HEIGHT = 0.12


@dataclass(frozen=True, slots=True)
class MarkerItem:
    """``kind`` is 'box', 'arrow' or 'text'; ``size`` is the box extent, the arrow's (length, width, width)
    or the text height; ``yaw`` rotates about z."""

    namespace: str
    kind: str
    center: tuple[float, float, float]
    size: tuple[float, float, float]
    color: tuple[float, float, float, float]
    yaw: float = 0.0
    text: str = ""


def _class_color(name: str) -> tuple[float, float, float, float]:
    red, green, blue = colorsys.hsv_to_rgb((zlib.crc32(name.encode()) % 360) / 360.0, 0.8, 0.95)
    return (red, green, blue, 0.9)


def world_markers(world: World) -> list[MarkerItem]:
    house = world.house
    items: list[MarkerItem] = []
    for wall in house.walls:
        (x0, y0), (x1, y1) = wall.start, wall.end
        size = (max(abs(x1 - x0), WALL_THICKNESS), max(abs(y1 - y0), WALL_THICKNESS), house.wall_height)
        items.append(MarkerItem("walls", "box", ((x0 + x1) / 2, (y0 + y1) / 2, house.wall_height / 2), size,
                                (0.75, 0.75, 0.72, 0.35)))
    for piece in house.furniture:
        items.append(MarkerItem("furniture", "box", tuple(float(v) for v in piece.box.center), piece.box.size,
                                (0.55, 0.4, 0.25, 0.6)))
    for item in world.objects:
        if item.carried:
            continue
        center = tuple(float(v) for v in item.position)
        items.append(MarkerItem("objects", "box", center, item.size, _class_color(item.class_name)))
        items.append(MarkerItem("object_labels", "text", (center[0], center[1], center[2] + item.size[2] / 2 + 0.1),
                                (LABEL_HEIGHT, LABEL_HEIGHT, LABEL_HEIGHT), (1.0, 1.0, 1.0, 1.0), text=item.id))
    for waypoint in house.waypoints:
        pose = waypoint.pose
        items.append(MarkerItem("waypoints", "arrow", (pose.x, pose.y, 0.05), (0.5, 0.08, 0.08),
                                (0.1, 0.6, 1.0, 0.9), pose.yaw))
        items.append(MarkerItem("waypoint_labels", "text", (pose.x, pose.y, 0.3),
                                (LABEL_HEIGHT, LABEL_HEIGHT, LABEL_HEIGHT), (0.1, 0.6, 1.0, 1.0), text=waypoint.name))
    return items


def yaw_to_quaternion(yaw: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a rotation by ``yaw`` about z."""
    return (0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))
