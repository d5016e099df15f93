"""What one call of the anchoring core changed: collected in order, then frozen into a result."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from merlin2_sailor.anchoring.anchor import Anchor
from merlin2_sailor.anchoring.events import AnchorEvent, AnchorEventKind
from merlin2_sailor.anchoring.frame_registration import FrameOffset


@dataclass(frozen=True, slots=True, eq=False)
class AnchoringResult:
    """What one call changed. ``percept_symbols[i]`` is the symbol percept i was anchored to, or ""
    for a percept left unresolved (too far to tell, :mod:`.far_view`; or held apart by a first view
    of another colour, :mod:`.colour_evidence`); ``unresolved`` names, per such percept, the
    anchor it may have been; ``frame_offset``: the shared pose error taken out of the frame's
    percepts before matching (:mod:`.frame_registration`), None when none was; ``held``: the
    percepts (indices) held out of matching, views of a row off its anchors by a pose error that
    could be read two ways (:func:`.frame_registration.read_frame`; their symbols are "")."""

    stamp: float
    acquired: tuple[Anchor, ...] = ()
    reacquired: tuple[Anchor, ...] = ()
    missing: tuple[Anchor, ...] = ()
    forgotten: tuple[Anchor, ...] = ()
    events: tuple[AnchorEvent, ...] = ()
    percept_symbols: tuple[str, ...] = ()
    unresolved: tuple[str, ...] = ()
    frame_offset: FrameOffset | None = None
    held: tuple[int, ...] = ()


@dataclass(slots=True)
class FrameChanges:
    """Collects one call's changes in order; :meth:`result` freezes them."""

    stamp: float
    acquired: list[Anchor] = field(default_factory=list)
    reacquired: list[Anchor] = field(default_factory=list)
    missing: list[Anchor] = field(default_factory=list)
    forgotten: list[Anchor] = field(default_factory=list)
    events: list[AnchorEvent] = field(default_factory=list)
    confirmed_newcomers: list[Anchor] = field(default_factory=list)
    """Anchors confirmed for the first time in this call (identity repair reads them): not part
    of the result."""
    returned: list[Anchor] = field(default_factory=list)
    """MISSING anchors confirmed again in this call (identity repair reads them): not part of the
    result."""

    def event(self, kind: AnchorEventKind, symbol: str, **details: Any) -> None:
        self.events.append(AnchorEvent(kind, symbol, self.stamp, details))

    def result(
        self, percept_symbols: Sequence[str] = (), unresolved: Sequence[str] = (),
        frame_offset: FrameOffset | None = None, held: Sequence[int] = (),
    ) -> AnchoringResult:
        return AnchoringResult(
            self.stamp,
            tuple(self.acquired),
            tuple(self.reacquired),
            tuple(self.missing),
            tuple(self.forgotten),
            tuple(self.events),
            tuple(percept_symbols),
            tuple(unresolved),
            frame_offset,
            tuple(held),
        )
