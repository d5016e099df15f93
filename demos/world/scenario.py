"""Scripted changes to the world: objects moved, added or removed while the robot is not looking.

Each event has a trigger (all its conditions must hold) and one change. Conditions read the
robot's progress: seconds since the start, arrivals at navigation goals, the waypoints arrived at
so far, and the room the robot is in. A due event waits until neither the object nor its
destination is in the camera's view, so the robot never sees an object teleport; it fires once.
"""

from __future__ import annotations

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


@dataclass(frozen=True, slots=True)
class Trigger:
    """All given conditions must hold; an empty trigger holds from the start."""

    after_seconds: float | None = None
    after_arrivals: int | None = None
    after_visiting: tuple[str, ...] = ()
    robot_in: tuple[str, ...] = ()
    robot_not_in: tuple[str, ...] = ()

    FIELDS = ("after_seconds", "after_arrivals", "after_visiting", "robot_in", "robot_not_in")

    def holds(self, progress: Progress) -> bool:
        return (
            (self.after_seconds is None or progress.time >= self.after_seconds)
            and (self.after_arrivals is None or progress.arrivals >= self.after_arrivals)
            and set(self.after_visiting) <= progress.visited
            and (not self.robot_in or progress.robot_room in self.robot_in)
            and progress.robot_room not in self.robot_not_in
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
        )


@dataclass(frozen=True, slots=True)
class ScenarioEvent:
    """One change: ``move`` ``object_id`` to ``destination``, ``add`` ``spec``, or ``remove`` ``object_id``."""

    name: str
    trigger: Trigger
    action: str
    object_id: str
    destination: tuple[float, float] | None = None
    spec: ObjectSpec | None = None

    @classmethod
    def from_mapping(cls, data: Any, where: str, textures: set[str]) -> ScenarioEvent:
        fields = Fields(data, where, ("name", "when", *ACTIONS))
        actions = [action for action in ACTIONS if fields.has(action)]
        if len(actions) != 1:
            raise ConfigurationError(f"{where}: an event needs exactly one of {list(ACTIONS)}, got {actions}")
        action = actions[0]
        trigger = Trigger.from_mapping(fields.raw("when", {}), f"{where}.when")
        if action == "add":
            spec = ObjectSpec.from_mapping(fields.raw("add"), f"{where}.add", textures)
            return cls(fields.text("name", f"add_{spec.id}"), trigger, action, spec.id, spec.xy, spec)
        change = Fields(fields.raw(action), f"{where}.{action}", ("object", "to") if action == "move" else ("object",))
        object_id = change.text("object")
        destination = change.vector("to", 2) if action == "move" else None
        return cls(fields.text("name", f"{action}_{object_id}"), trigger, action, object_id,
                   None if destination is None else (destination[0], destination[1]))


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
    """The events still to fire, in file order, and those fired."""

    events: tuple[ScenarioEvent, ...] = ()
    fired: list[FiredEvent] = field(default_factory=list)

    def __post_init__(self) -> None:
        self._pending = list(self.events)

    @property
    def pending(self) -> tuple[ScenarioEvent, ...]:
        return tuple(self._pending)

    def due(self, progress: Progress) -> list[ScenarioEvent]:
        """Events whose trigger holds now, not yet fired."""
        return [event for event in self._pending if event.trigger.holds(progress)]

    def record(self, event: ScenarioEvent, fired: FiredEvent) -> None:
        self._pending.remove(event)
        self.fired.append(fired)
