"""The ``mission`` section of a world file: the demo's job in that world, and its right outcome.

The mission demo node runs it (explore, a route while the world changes, then "find the target
and go to it") and the scorecard judges the run against ``expect``. A world file without the
section gets :class:`MissionSpec`'s defaults, the story of the default demo::

    mission:
      target: red_mug               # world id of the object to find (it must exist at the start)
      explore: [kitchen, hall]      # waypoints to explore first (default: every waypoint)
      route:                        # then, in turn: go to a waypoint (optional) and wait for the
        - {go_to: hall, wait_for: [red_mug_moves]}   # named scenario events (default: every
                                                     # event not fired yet)
      expect:
        outcome: found              # found (under the symbol it had) or not_found (it is gone)
        unknown_allowed: false      # "cannot tell apart" counts as right (true twins)
        keep_symbols: [green_mug_living]   # these end under the symbols they had before
        new_symbols: [red_mug_2]           # these end under symbols no object had before
        anchored_once: [book_1, book_2]    # exactly one anchor refers to each of these
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum
from typing import Any

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor_demos.world.yaml_fields import Fields


class ExpectedOutcome(Enum):
    FOUND = "found"
    """The target is found under the symbol it was anchored with before the change."""
    NOT_FOUND = "not_found"
    """The target is gone: the mission must say so, and never claim another object."""


@dataclass(frozen=True)
class Expectation:
    """The right outcome of a mission; see the module docstring for each field."""

    outcome: ExpectedOutcome = ExpectedOutcome.FOUND
    unknown_allowed: bool = False
    keep_symbols: tuple[str, ...] = ()
    new_symbols: tuple[str, ...] = ()
    anchored_once: tuple[str, ...] = ()

    FIELDS = ("outcome", "unknown_allowed", "keep_symbols", "new_symbols", "anchored_once")

    @property
    def object_ids(self) -> tuple[str, ...]:
        """Every object id the expectation names."""
        return self.keep_symbols + self.new_symbols + self.anchored_once

    @classmethod
    def from_mapping(cls, data: Any, where: str) -> Expectation:
        fields = Fields(data or {}, where, cls.FIELDS)
        name = fields.text("outcome", ExpectedOutcome.FOUND.value)
        try:
            outcome = ExpectedOutcome(name)
        except ValueError:
            choices = ", ".join(item.value for item in ExpectedOutcome)
            raise ConfigurationError(f"{where}: 'outcome' must be one of {choices}, got {name!r}") from None
        return cls(outcome, fields.boolean("unknown_allowed", False), fields.names("keep_symbols", ()),
                   fields.names("new_symbols", ()), fields.names("anchored_once", ()))

    def as_dict(self) -> dict[str, Any]:
        return {"outcome": self.outcome.value, "unknown_allowed": self.unknown_allowed,
                "keep_symbols": list(self.keep_symbols), "new_symbols": list(self.new_symbols),
                "anchored_once": list(self.anchored_once)}


@dataclass(frozen=True)
class RouteStop:
    """Go to ``go_to`` (None: stay) and wait for ``wait_for`` to fire (None: every pending event)."""

    go_to: str | None = None
    wait_for: tuple[str, ...] | None = None

    @classmethod
    def from_mapping(cls, data: Any, where: str) -> RouteStop:
        fields = Fields(data, where, ("go_to", "wait_for"))
        wait_for = fields.names("wait_for") if fields.has("wait_for") else None
        return cls(fields.text("go_to", None), wait_for)


@dataclass(frozen=True)
class MissionSpec:
    """What the mission demo does in a world, and what it should end with."""

    target: str = "red_mug"
    explore: tuple[str, ...] | None = None
    """Waypoints to explore before the route; None: every waypoint of the grounding."""
    route: tuple[RouteStop, ...] = (RouteStop("hall"),)
    expect: Expectation = field(default_factory=Expectation)

    FIELDS = ("target", "explore", "route", "expect")

    @classmethod
    def from_mapping(cls, data: Any, where: str) -> MissionSpec:
        fields = Fields(data or {}, where, cls.FIELDS)
        default = cls()
        route_data = fields.sequence("route") if fields.has("route") else None
        route = default.route if route_data is None else tuple(
            RouteStop.from_mapping(item, f"{where}.route[{index}]") for index, item in enumerate(route_data))
        return cls(
            fields.text("target", default.target),
            fields.names("explore", ()) if fields.has("explore") else None,
            route,
            Expectation.from_mapping(fields.raw("expect", {}), f"{where}.expect"),
        )

    def check(self, objects: set[str], added: set[str], waypoints: set[str], events: set[str], where: str) -> None:
        """Every name the mission uses exists: ``objects`` at the start, ``added`` by events."""
        if self.target not in objects:
            raise ConfigurationError(f"{where}: the target '{self.target}' is not an object at the start "
                                     f"(objects: {sorted(objects)})")
        unknown = sorted(set(self.expect.object_ids) - objects - added)
        if unknown:
            raise ConfigurationError(f"{where}.expect: no object(s) {unknown}")
        named = [*(self.explore or ()), *(stop.go_to for stop in self.route if stop.go_to)]
        unknown = sorted(set(named) - waypoints)
        if unknown:
            raise ConfigurationError(f"{where}: unknown waypoint(s) {unknown}; waypoints: {sorted(waypoints)}")
        awaited = {name for stop in self.route for name in stop.wait_for or ()}
        unknown = sorted(awaited - events)
        if unknown:
            raise ConfigurationError(f"{where}.route: waits for unknown event(s) {unknown}; events: {sorted(events)}")

    def as_dict(self) -> dict[str, Any]:
        return {
            "target": self.target, "explore": None if self.explore is None else list(self.explore),
            "route": [{"go_to": stop.go_to, "wait_for": None if stop.wait_for is None else list(stop.wait_for)}
                      for stop in self.route],
            "expect": self.expect.as_dict(),
        }
