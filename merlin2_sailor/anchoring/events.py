"""What happened to an anchor, as a record the ROS node can publish and the tests can check.

Every change of an anchor's identity or lifecycle state produces one :class:`AnchorEvent`, so
downstream consumers (the knowledge-base sync, a monitor, a test) learn about changes from one
ordered list rather than by diffing anchors between frames.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from enum import Enum
from types import MappingProxyType
from typing import Any


class AnchorEventKind(Enum):
    """The kinds of change an anchor goes through."""

    ACQUIRED = "acquired"
    """A percept matched no anchor: a new anchor (and symbol) was created."""
    REACQUIRED = "reacquired"
    """A percept matched an existing anchor, which fused it."""
    CONFIRMED = "confirmed"
    """Seen often enough to be trusted, or an expected location was seen to hold."""
    MISSING = "missing"
    """Should have been visible (in the frustum, not occluded) but was not seen."""
    FORGOTTEN = "forgotten"
    """Missing for too long, or forgotten on request: the anchor and its symbol are gone. When it
    was found to be another anchor's object (merged, a duplicate, a part joined), ``details["into"]``
    names that anchor, so a listener can follow the symbol without parsing the reason."""
    RETRACTED = "retracted"
    """An expected location was contradicted by what the camera saw."""
    AMBIGUOUS = "ambiguous"
    """The evidence cannot tell which of several anchors an object is (look-alikes): no merge was
    made, and ``details`` name the candidates; the identity stays unknown rather than guessed."""


@dataclass(frozen=True, slots=True)
class AnchorEvent:
    """One change of one anchor at one time; ``details`` says why, in plain data."""

    kind: AnchorEventKind
    symbol: str
    stamp: float
    details: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))

    def __post_init__(self) -> None:
        object.__setattr__(self, "details", MappingProxyType(dict(self.details)))
