"""Which world object an anchor refers to: the one it last saw, not the one standing there now.

An anchor not seen since the world changed still stands where its object was; by position
alone, an object moved onto that spot would take its symbol, and a scorecard would blame the
anchoring for a confusion the robot never had a chance to make. So a symbol refers to the object
that was nearest its anchor (same class, within ``max_distance``) at the anchor's last sighting,
in the ground truth as it was then: the timeline keeps every version of the truth with the stamp
the world changed it at.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from merlin2_sailor_demos.report.scorecard import AnchorRecord, TrueObject

#: How far (m) an anchor may be from the object it refers to, as the scorecard's association.
REFERS_DISTANCE = 0.5


@dataclass
class TruthTimeline:
    """The ground truth's versions, each from the stamp (s) it took effect."""

    stamps: list[float] = field(default_factory=list)
    versions: list[tuple[TrueObject, ...]] = field(default_factory=list)

    def record(self, stamp: float, truth: Sequence[TrueObject]) -> None:
        """Add a version; the same truth again, or one stamped before the last, is ignored."""
        truth = tuple(truth)
        if self.versions and (truth == self.versions[-1] or stamp < self.stamps[-1]):
            return
        self.stamps.append(stamp)
        self.versions.append(truth)

    def at(self, stamp: float) -> tuple[TrueObject, ...]:
        """The truth in force at ``stamp`` (the first version for a stamp before it)."""
        if not self.versions:
            return ()
        index = bisect.bisect_right(self.stamps, stamp) - 1
        return self.versions[max(index, 0)]


def refers_to(anchor: AnchorRecord, last_seen: float, timeline: TruthTimeline,
              max_distance: float = REFERS_DISTANCE) -> str | None:
    """The id of the object ``anchor`` refers to (nearest of its class at its last sighting), or None."""
    return nearest_of_class(anchor, timeline.at(last_seen), lambda obj: (math.dist(obj.position, anchor.position),),
                            max_distance)


def nearest_of_class(anchor: AnchorRecord, truth: Sequence[TrueObject],
                     measure: Callable[[TrueObject], tuple[float, ...]], max_distance: float) -> str | None:
    """The id of the object of ``anchor``'s class with the least ``measure`` (a distance first, then
    what breaks its ties) whose distance is within ``max_distance``; the later of equals; None: none."""
    best, best_measure = None, (max_distance, math.inf)
    for obj in truth:
        if obj.class_name != anchor.class_name:
            continue
        measured = measure(obj)
        if measured[0] <= max_distance and measured <= best_measure:
            best, best_measure = obj.id, measured
    return best
