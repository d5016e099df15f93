"""What every behaviour is built with: its ports to the robot, the map, the store and its settings.

A state machine factory takes one :class:`BehaviorContext` and nothing else, so the same factory
builds the machine a ROS action server runs, the one a MERLIN2 adapter runs and the one a unit
test runs with fakes.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass, field

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.knowledge import KnowledgeBase
from merlin2_sailor_behaviors.actions.clients import AnchoringPort, GraspPort, NavigationPort
from merlin2_sailor_behaviors.actions.look_history import LookHistory
from merlin2_sailor_behaviors.actions.places import Places

Log = Callable[[str, str], None]
"""``log(level, message)`` with level ``debug``, ``info``, ``warning`` or ``error``."""

_logger = logging.getLogger("merlin2_sailor_behaviors")


def python_log(level: str, message: str) -> None:
    """The default log: Python's logging, under ``merlin2_sailor_behaviors``."""
    getattr(_logger, level, _logger.info)(message)


@dataclass(frozen=True)
class BehaviorConfig:
    """The behaviours' settings; every duration is in seconds, every distance in metres."""

    look_around_turns: int = 4
    """Goals to turn in place through 360 degrees when looking around; 0 only dwells."""
    look_dwell: float = 1.0
    """How long to stand still after each turn (and, with no turns, in all), so the camera sees."""
    approach_timeout: float = 10.0
    """approach_object: how long to wait for the camera to reacquire the object it faces."""
    reacquire_timeout: float = 3.0
    """find_object: how long to wait at each stop, after looking around, for a reacquisition."""
    search_radius: float = 3.0
    """find_object: how far from a stop (other than where the object was last anchored) the
    object is searched for: a percept of its class anywhere that close may reacquire it. About
    a room's half-diagonal; 0 expects it exactly at the stop's point."""
    look_fresh_for: float = 30.0
    """explore: a complete look-around at the same waypoint this recently (by navigation, on
    arrival) counts, and is not repeated; 0 always looks."""
    confirm_timeout: float = 5.0
    """bring: how long to look at the placed object for perception to confirm it."""
    poll_period: float = 0.2
    """How often to ask the anchoring layer while waiting for a sighting."""
    carry_offset: tuple[float, float, float] = (0.2, 0.0, 0.8)
    """bring: where a carried object is, in the robot's base frame (EXPECT_CARRIED)."""
    place_distance: float = 0.5
    """bring: how far in front of the robot the object is put down."""
    return_on_failure: bool = True
    """find_object: drive back to the origin when the object was not found anywhere, so the
    origin the dispatcher restores is where the robot is."""

    def __post_init__(self) -> None:
        if self.look_around_turns < 0 or self.look_around_turns == 1:
            raise ConfigurationError(
                f"look_around_turns must be 0 (dwell only) or 2 or more, got {self.look_around_turns}"
            )
        for name in ("look_dwell", "approach_timeout", "reacquire_timeout", "search_radius", "confirm_timeout",
                     "place_distance", "look_fresh_for"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise ConfigurationError(f"{name} must be a finite number >= 0, got {value!r}")
        if not (math.isfinite(self.poll_period) and self.poll_period > 0):
            raise ConfigurationError(f"poll_period must be positive, got {self.poll_period!r}")
        offset = tuple(float(value) for value in self.carry_offset)
        if len(offset) != 3 or not all(math.isfinite(value) for value in offset):
            raise ConfigurationError(f"carry_offset must be 3 finite numbers, got {self.carry_offset!r}")
        object.__setattr__(self, "carry_offset", offset)


@dataclass(frozen=True)
class BehaviorContext:
    """Everything a behaviour's states use; built once per process, shared by every run."""

    store: KnowledgeBase
    anchoring: AnchoringPort
    navigation: NavigationPort
    grasp: GraspPort
    places: Places
    config: BehaviorConfig = field(default_factory=BehaviorConfig)
    log: Log = python_log
    looks: LookHistory = field(default_factory=LookHistory)
    """The latest complete look-around, shared by the behaviours (explore skips a fresh one)."""
