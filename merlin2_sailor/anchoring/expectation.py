"""Where an action expects an object to be: a prediction that perception confirms or retracts.

Behaviours announce the effects they expect (a pick: "the cup is carried by the robot"; a place:
"the cup is at the kitchen table"). The anchoring layer moves the anchor to the expected place
with provenance EXPECTED, so a top-down Find looks in the right place, and then lets the camera
decide: reacquired near the expected place confirms it, the place seen empty retracts it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from enum import Enum
from typing import Any

import numpy as np

from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import InvalidInputError


class ExpectationKind(Enum):
    AT = "at"
    """At a fixed place of the world frame (a position or a waypoint)."""
    CARRIED = "carried"
    """Carried by the robot: follows the robot pose at a fixed offset in the robot frame."""


@dataclass(frozen=True, slots=True, eq=False)
class Expectation:
    """An expected location. Build one with :meth:`at` or :meth:`carried`.

    ``position`` is the world position for AT and the offset in the robot's frame for CARRIED.
    ``place`` names the waypoint or region when there is one; ``source`` names the action that
    announced it. Both only travel into event details, for whoever has to explain a retraction.

    ``radius`` > 0 makes an AT expectation a search (top-down Find): "it may be somewhere within
    ``radius`` of ``position``". The matching table then counts a percept anywhere in that disc
    as close, with a score capped below that of an anchor seen in place, so a look-alike already
    anchored there keeps its own percept. A search is never retracted by an empty view (the
    searcher cannot know which part of the disc the camera covered); the searcher clears it.
    """

    kind: ExpectationKind
    position: np.ndarray
    stamp: float
    place: str = ""
    source: str = ""
    radius: float = 0.0

    def __post_init__(self) -> None:
        position = np.array(self.position, dtype=np.float64).reshape(-1)
        if position.shape != (3,) or not np.all(np.isfinite(position)):
            raise InvalidInputError(
                f"An expected {self.kind.value} position needs 3 finite values, "
                f"got {np.asarray(self.position).tolist()}."
            )
        if not (math.isfinite(self.radius) and self.radius >= 0.0):
            raise InvalidInputError(f"An expectation's search radius must be >= 0 metres, got {self.radius}.")
        if self.radius > 0.0 and self.kind is not ExpectationKind.AT:
            raise InvalidInputError("Only an expectation at a place can be a search with a radius.")
        if not np.isfinite(self.stamp):
            raise InvalidInputError(f"An expectation's stamp must be finite, got {self.stamp}.")
        position.setflags(write=False)
        object.__setattr__(self, "position", position)

    @classmethod
    def at(
        cls, position: np.ndarray, stamp: float, place: str = "", source: str = "", radius: float = 0.0
    ) -> Expectation:
        """The object is expected at ``position`` (world frame), or within ``radius`` of it (a search)."""
        return cls(ExpectationKind.AT, np.asarray(position, dtype=np.float64), stamp, place, source, float(radius))

    @property
    def is_search(self) -> bool:
        """Whether this is a top-down search over a disc rather than a predicted place."""
        return self.radius > 0.0

    @classmethod
    def carried(
        cls, stamp: float, offset: np.ndarray | tuple[float, float, float] = (0.0, 0.0, 0.0), source: str = ""
    ) -> Expectation:
        """The object is expected to move with the robot, ``offset`` metres from its base frame."""
        return cls(ExpectationKind.CARRIED, np.asarray(offset, dtype=np.float64), stamp, "", source)

    def expected_position(self, robot_pose: Pose | None) -> np.ndarray | None:
        """Where the object should be now; None for a carried object when no robot pose is known."""
        if self.kind is ExpectationKind.AT:
            return self.position.copy()
        if robot_pose is None:
            return None
        return robot_pose.transform_points(self.position)

    def describe(self) -> dict[str, object]:
        """Plain data for event details and snapshots."""
        return {
            "kind": self.kind.value,
            "position": self.position.tolist(),
            "stamp": float(self.stamp),
            "place": self.place,
            "source": self.source,
            "radius": self.radius,
        }

    @classmethod
    def from_description(cls, description: Mapping[str, Any]) -> Expectation:
        try:
            kind = ExpectationKind(description["kind"])
            return cls(
                kind,
                np.asarray(description["position"], dtype=np.float64),
                float(description["stamp"]),
                str(description.get("place", "")),
                str(description.get("source", "")),
                float(description.get("radius", 0.0)),
            )
        except (KeyError, ValueError, TypeError) as error:
            raise InvalidInputError(f"Malformed expectation {description!r}: {error}.") from error
