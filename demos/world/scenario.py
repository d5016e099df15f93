"""Scripted changes to the world: objects moved, added or removed, unseen or before the camera.

Each event has a trigger (all its conditions must hold) and one change. Conditions read the
robot's progress: seconds since the start, arrivals at navigation goals, the waypoints arrived at
so far (or, with ``after_event``, arrived at since that event fired: "moved back once the
robot has been to the kitchen again"), the room the robot is in, and how long it has stood
still. A due event waits until
neither the object nor its destination is in the camera's view, so the robot never sees an
object teleport; a ``watched`` event waits for the opposite, both in view. A move with a
``speed`` (m/s) glides there in a straight line instead of jumping, so a camera that watches
sees the object travel. Each event fires once; a glide counts as fired when it arrives.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor_demos.world.objects import ObjectSpec
from merlin2_sailor_demos.world.yaml_fields import Fields

ACTIONS = ("move", "add", "remove")


@dataclass(frozen=True, slots=True)
class Progress:
    """What triggers read: time (s), arrivals so far, waypoints arrived at, the robot's room."""

    time: float
    arrivals: int
    visited: frozenset[str]
    robot_room: str | None
    still_for: float = 0.0
    """Seconds since the robot last moved or turned."""
    visited_since: Mapping[str, frozenset[str]] = field(default_factory=dict)
    """For each fired event, the waypoints arrived at since it fired."""


@dataclass(frozen=True, slots=True)
class Trigger:
    """All given conditions must hold; an empty trigger holds from the start."""

    after_seconds: float | None = None
    after_arrivals: int | None = None
    after_visiting: tuple[str, ...] = ()
    robot_in: tuple[str, ...] = ()
    robot_not_in: tuple[str, ...] = ()
    robot_still_for: float | None = None
    after_event: str | None = None

    FIELDS = ("after_seconds", "after_arrivals", "after_visiting", "robot_in", "robot_not_in", "robot_still_for",
              "after_event")

    def holds(self, progress: Progress) -> bool:
        if self.after_event is not None and self.after_event not in progress.visited_since:
            return False
        visited = progress.visited if self.after_event is None else progress.visited_since[self.after_event]
        return (
            (self.after_seconds is None or progress.time >= self.after_seconds)
            and (self.after_arrivals is None or progress.arrivals >= self.after_arrivals)
            and set(self.after_visiting) <= visited
            and (not self.robot_in or progress.robot_room in self.robot_in)
            and progress.robot_room not in self.robot_not_in
            and (self.robot_still_for is None or progress.still_for >= self.robot_still_for)
        )

    @classmethod
    def from_mapping(cls, data: Any, where: str) -> Trigger:
        fields = Fields(data or {}, where, cls.FIELDS)
        return cls(
            fields.number("after_seconds", None, minimum=0.0),
            fields.integer("after_arrivals", None, minimum=0),
            fields.names("after_visiting", ()),
            fields.names("robot_in", ()),
            fields.names("robot_not_in", ()),
            fields.number("robot_still_for", None, minimum=0.0),
            fields.text("after_event", None),
        )


@dataclass(frozen=True, slots=True)
class ScenarioEvent:
    """One change: ``move`` ``object_id`` to ``destination`` (gliding at ``speed`` m/s when given),
    ``add`` ``spec``, or ``remove`` ``object_id``; ``watched``: only while the camera sees it."""

    name: str
    trigger: Trigger
    action: str
    object_id: str
    destination: tuple[float, float] | None = None
    spec: ObjectSpec | None = None
    speed: float | None = None
    watched: bool = False

    @classmethod
    def from_mapping(cls, data: Any, where: str, textures: set[str]) -> ScenarioEvent:
        fields = Fields(data, where, ("name", "when", "watched", *ACTIONS))
        watched = fields.boolean("watched", False)
        actions = [action for action in ACTIONS if fields.has(action)]
        if len(actions) != 1:
            raise ConfigurationError(f"{where}: an event needs exactly one of {list(ACTIONS)}, got {actions}")
        action = actions[0]
        trigger = Trigger.from_mapping(fields.raw("when", {}), f"{where}.when")
        if action == "add":
            spec = ObjectSpec.from_mapping(fields.raw("add"), f"{where}.add", textures)
            return cls(fields.text("name", f"add_{spec.id}"), trigger, action, spec.id, spec.xy, spec,
                       watched=watched)
        moving = action == "move"
        change = Fields(fields.raw(action), f"{where}.{action}", ("object", "to", "speed") if moving else ("object",))
        object_id = change.text("object")
        destination = change.vector("to", 2) if moving else None
        speed = change.number("speed", None, minimum=0.01, maximum=5.0) if moving else None
        return cls(fields.text("name", f"{action}_{object_id}"), trigger, action, object_id,
                   None if destination is None else (destination[0], destination[1]), speed=speed, watched=watched)


@dataclass(frozen=True, slots=True)
class FiredEvent:
    name: str
    action: str
    object_id: str
    time: float
    source: tuple[float, float, float] | None
    destination: tuple[float, float, float] | None

    def as_dict(self) -> dict[str, Any]:
        return {"name": self.name, "action": self.action, "object": self.object_id, "time": round(self.time, 3),
                "from": None if self.source is None else [round(v, 4) for v in self.source],
                "to": None if self.destination is None else [round(v, 4) for v in self.destination]}


@dataclass
class Scenario:
    """The events still to fire, in file order, those under way (gliding) and those fired."""

    events: tuple[ScenarioEvent, ...] = ()
    fired: list[FiredEvent] = field(default_factory=list)

    def __post_init__(self) -> None:
        self._waiting = list(self.events)
        self._under_way: list[ScenarioEvent] = []

    @property
    def pending(self) -> tuple[ScenarioEvent, ...]:
        """Events not fired yet: waiting for their trigger, or under way."""
        return tuple(self._under_way) + tuple(self._waiting)

    def due(self, progress: Progress) -> list[ScenarioEvent]:
        """Events whose trigger holds now, neither started nor fired."""
        return [event for event in self._waiting if event.trigger.holds(progress)]

    def start(self, event: ScenarioEvent) -> None:
        """``event`` began (a glide): no longer due, not yet fired."""
        self._waiting.remove(event)
        self._under_way.append(event)

    def record(self, event: ScenarioEvent, fired: FiredEvent) -> None:
        if event in self._under_way:
            self._under_way.remove(event)
        else:
            self._waiting.remove(event)
        self.fired.append(fired)
