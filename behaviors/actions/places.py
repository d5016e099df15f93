"""Where the map's named places are: the waypoints (and regions) of the grounding configuration.

Behaviours read the same :class:`~merlin2_sailor.knowledge.grounding.GroundingConfig` the
anchoring layer grounds with, so ``object_at(cup_1, kitchen)`` and a navigation to ``kitchen``
mean the same point. A waypoint may give a heading (``yaw``, radians); a region is reached at its
centre, with no heading.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

from merlin2_sailor.knowledge.grounding import GroundingConfig
from merlin2_sailor_behaviors.actions.errors import BehaviorError


@dataclass(frozen=True)
class Place:
    """A named point of the map; ``yaw`` is None when the map gives no heading."""

    name: str
    x: float
    y: float
    yaw: float | None = None
    is_waypoint: bool = True

    def distance_to(self, x: float, y: float) -> float:
        return math.hypot(self.x - x, self.y - y)


class Places:
    """The map's places by name, and which waypoints are nearest a point."""

    def __init__(self, places: Iterable[Place]) -> None:
        self._places = {place.name: place for place in places}
        bad = [p.name for p in self._places.values() if not (math.isfinite(p.x) and math.isfinite(p.y))]
        if bad:
            raise BehaviorError(f"places {bad} have coordinates that are not finite numbers; fix the map")

    @classmethod
    def from_grounding(cls, config: GroundingConfig) -> Places:
        """Waypoints (with their ``yaw`` when the configuration has one) and region centres."""
        places = [
            Place(w.name, w.x, w.y, _optional_yaw(getattr(w, "yaw", None))) for w in config.waypoints
        ]
        places += [
            Place(r.name, (r.x_min + r.x_max) / 2.0, (r.y_min + r.y_max) / 2.0, is_waypoint=False)
            for r in config.regions
        ]
        return cls(places)

    def names(self) -> tuple[str, ...]:
        return tuple(self._places)

    def waypoint_names(self) -> tuple[str, ...]:
        return tuple(name for name, place in self._places.items() if place.is_waypoint)

    def get(self, name: str) -> Place:
        """The place called ``name``, or a BehaviorError listing the known ones."""
        place = self._places.get(name)
        if place is None:
            raise BehaviorError(
                f"unknown place {name!r}: the map (grounding configuration) knows "
                f"{sorted(self._places) or 'no place at all'}"
            )
        return place

    def nearest_waypoint(self, x: float, y: float) -> str | None:
        """The waypoint nearest (x, y), None when the map has none or the point is not finite."""
        ranked = self.waypoints_by_distance(x, y)
        return ranked[0] if ranked else None

    def waypoints_by_distance(self, x: float, y: float) -> list[str]:
        """Every waypoint, nearest (x, y) first (ties by name, so the order is stable)."""
        if not (math.isfinite(x) and math.isfinite(y)):
            return []
        waypoints = [place for place in self._places.values() if place.is_waypoint]
        waypoints.sort(key=lambda place: (place.distance_to(x, y), place.name))
        return [place.name for place in waypoints]

    def tour(self, start: str, others: Iterable[str]) -> list[str]:
        """``start`` then ``others``, each next stop the nearest not yet visited to the last one
        (greedy nearest neighbour: short drives between search stops)."""
        route = [start]
        remaining = [name for name in dict.fromkeys(others) if name != start]
        while remaining:
            last = self.get(route[-1])
            remaining.sort(key=lambda name: (self.get(name).distance_to(last.x, last.y), name))
            route.append(remaining.pop(0))
        return route


def _optional_yaw(value: object) -> float | None:
    if value is None:
        return None
    yaw = float(value)  # type: ignore[arg-type]
    return yaw if math.isfinite(yaw) else None
