"""What behaviours ask of the rest of the robot, as three small ports with plain data.

States are written against these protocols, never against ROS: the ROS implementations live in
:mod:`merlin2_sailor_behaviors.ros` (service and action clients handed a node late), and the unit
tests pass fakes. Every method either answers or raises
:class:`~merlin2_sailor_behaviors.actions.errors.BehaviorError` with a sentence saying what is
unreachable; a refusal that is part of the conversation (a grasp that finds nothing, a goal the
navigation rejects) is an answer, not an error.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from enum import Enum
from typing import Protocol

from merlin2_sailor.anchoring.anchor import AnchorState
from merlin2_sailor_behaviors.actions.errors import BehaviorError

Point = tuple[float, float, float]
"""A position in the world frame, in metres."""


def finite_point(values: tuple[float, ...] | list[float], what: str) -> Point:
    """``values`` as a 3D point, or a BehaviorError naming ``what`` when a value is not finite."""
    point = tuple(float(value) for value in values)
    if len(point) != 3 or not all(math.isfinite(value) for value in point):
        raise BehaviorError(f"{what} must be 3 finite numbers, got {list(values)}")
    return point  # type: ignore[return-value]


@dataclass(frozen=True)
class Pose2D:
    """A robot pose on the map: position in metres, heading (yaw) in radians."""

    x: float
    y: float
    yaw: float = 0.0

    def __post_init__(self) -> None:
        if not all(math.isfinite(value) for value in (self.x, self.y, self.yaw)):
            raise BehaviorError(
                f"a pose needs finite x, y and yaw, got ({self.x}, {self.y}, {self.yaw}); "
                "check the waypoint or the robot pose it came from"
            )

    def facing(self, x: float, y: float) -> Pose2D:
        """This position, turned towards the point (x, y); unchanged when already on it."""
        if math.hypot(x - self.x, y - self.y) < 1e-6:
            return self
        return Pose2D(self.x, self.y, math.atan2(y - self.y, x - self.x))

    def turned(self, angle: float) -> Pose2D:
        """This position with the heading turned by ``angle`` radians, wrapped to (-pi, pi]."""
        yaw = math.atan2(math.sin(self.yaw + angle), math.cos(self.yaw + angle))
        return Pose2D(self.x, self.y, yaw)

    def ahead(self, distance: float) -> tuple[float, float]:
        """The point ``distance`` metres in front of this pose."""
        return (self.x + distance * math.cos(self.yaw), self.y + distance * math.sin(self.yaw))


@dataclass(frozen=True)
class AnchorReport:
    """An anchor as the anchoring node reports it: enough to find, face and confirm an object."""

    symbol: str
    class_name: str
    state: AnchorState
    position: Point
    last_seen: float
    """When it was last perceived, in the anchoring node's clock (seconds): its latest sighting
    nothing since has put in doubt (the ``Anchor`` message's ``last_seen``)."""
    times_seen: int = 0
    indistinguishable_from: tuple[str, ...] = ()
    """While missing: anchors a search found that the anchoring layer cannot tell from this one
    (look-alikes). Its identity is unknown: a finder must not claim any of them is it."""
    found_by_look_alone: str = ""
    """While missing: an anchor a search found that looks like this one, where the camera had never
    watched before (a copy may have stood there all along). The anchoring layer takes it for this
    one only when the finder, having looked everywhere else and seen no other copy, concludes the
    search (:meth:`AnchoringPort.conclude_search`); empty: none."""

    def seen_since(self, baseline: AnchorReport | None) -> bool:
        """Whether the camera reacquired this anchor after ``baseline`` was taken (None: ever),
        and it is trusted. Comparing two of the node's own stamps needs no shared clock."""
        if self.state is not AnchorState.CONFIRMED:
            return False
        return baseline is None or self.last_seen > baseline.last_seen


class AnchoringPort(Protocol):
    """The anchoring node's services: read anchors, find one top-down, announce expectations."""

    def get_anchor(self, symbol: str) -> AnchorReport | None:
        """The anchor with this symbol, None when the anchoring layer has none."""
        ...

    def get_anchors(self, class_name: str = "") -> tuple[AnchorReport, ...]:
        """Every anchor, or those of one class."""
        ...

    def find_anchor(
        self, symbol: str = "", class_name: str = "", near: Point | None = None
    ) -> AnchorReport | None:
        """Top-down Find: the best anchor for a symbol, or for a class (nearest ``near``)."""
        ...

    def expect_at(self, symbol: str, position: Point, place: str, source: str, radius: float = 0.0) -> None:
        """Announce that the object is expected at ``position`` (the waypoint ``place``), or, with
        a ``radius``, that it is being searched for anywhere within that many metres of it."""
        ...

    def expect_carried(self, symbol: str, offset: Point, source: str) -> None:
        """Announce that the robot carries the object, ``offset`` metres from its base."""
        ...

    def clear_expectation(self, symbol: str, source: str) -> None:
        """Withdraw an expectation that no longer applies."""
        ...

    def conclude_search(self, symbol: str, source: str) -> bool:
        """Say that a search for ``symbol`` has looked everywhere: the anchoring layer takes the
        anchor it found by look alone (``found_by_look_alone``) for it, unless a copy turned up
        meanwhile. Whether it did."""
        ...


class NavigationStatus(Enum):
    """How a NavigateToPose goal ended."""

    ARRIVED = "arrived"
    CANCELED = "canceled"
    FAILED = "failed"


@dataclass(frozen=True)
class NavigationResult:
    """The end of a navigation goal; ``message`` says why when it did not arrive."""

    status: NavigationStatus
    message: str = ""


class NavigationPort(Protocol):
    """Nav2's NavigateToPose (and MERLIN2's waypoint navigation, where the robot has it), plus the
    robot's current pose."""

    def navigate(self, goal: Pose2D, should_cancel: Callable[[], bool], waypoint: str = "") -> NavigationResult:
        """Drive to ``goal`` and wait; cancel the goal as soon as ``should_cancel()`` is true.
        ``waypoint`` names ``goal`` when it is a waypoint of the map, for a navigation that drives
        to waypoints by name."""
        ...

    def robot_pose(self) -> Pose2D | None:
        """The latest robot pose on the map, None before the first one arrives."""
        ...


@dataclass(frozen=True)
class GraspResult:
    """Whether a pick or place worked, and why not."""

    success: bool
    message: str = ""


class GraspPort(Protocol):
    """A gripper: pick the object of a class nearest a point, place the held one at a point."""

    def pick(self, class_name: str, target: Point) -> GraspResult: ...

    def place(self, target: Point) -> GraspResult: ...
