"""AnchorView: an immutable copy of what other threads may read of an anchor.

The anchoring core mutates anchors in place on every frame. The knowledge-base sync and the
state file run off the perception hot path, in another thread, and the node publishes anchors and
answers services from other threads than the one anchoring frames; so they all get frozen copies
taken under the service's lock, never the live anchors. A view satisfies the grounding protocols
(``GroundableAnchor`` and ``SizedAnchor``).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.anchoring.anchor import Anchor, AnchorState


@dataclass(frozen=True, eq=False)
class AnchorView:
    """What an anchor was at one instant: enough for grounding, the knowledge-base sync, the
    state published to other nodes (messages, markers) and service answers."""

    symbol: str
    class_name: str
    position: np.ndarray
    size: np.ndarray
    state: AnchorState
    visible: bool
    confidence: float
    times_seen: int
    last_tracker_id: str
    first_seen: float
    last_seen: float
    """Its latest sighting that nothing since has put in doubt (:attr:`.Anchor.last_sure_sighting`)."""
    indistinguishable_from: tuple[str, ...] = ()
    found_by_look_alone: str = ""

    @classmethod
    def of(cls, anchor: Anchor) -> AnchorView:
        position, size = anchor.position.copy(), anchor.size.copy()
        position.flags.writeable = size.flags.writeable = False
        return cls(anchor.symbol, anchor.class_name, position, size, anchor.state, anchor.visible,
                   anchor.confidence, anchor.times_seen, anchor.last_tracker_id, anchor.first_seen,
                   anchor.last_sure_sighting, anchor.indistinguishable_from, anchor.found_by_look_alone)


def views_of(anchors: Iterable[Anchor]) -> list[AnchorView]:
    return [AnchorView.of(anchor) for anchor in anchors]
