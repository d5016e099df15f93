"""Was an anchor merged into another object's symbol? Every merge the anchoring layer made, judged.

A scorecard that judges only the target's claim misses a neighbour's symbol forgotten into another
object's: the living room's bicycle, whose anchor a same-space merge and then a join of parts
folded into the wheeled bicycle's, ended with no symbol at all, and the run counted right
(`bicycle_wheeled_beside_another`, network, seed 2, 7 December 2026). So the demo notes every
FORGOTTEN event that names the anchor it was taken for (``details["into"]``: merges, duplicates,
parts joined) and judges it by the object each of the two anchors was first the anchor of: the
nearest object of its class, within :data:`~.truth_timeline.REFERS_DISTANCE` of the object's
footprint, at the first sighting that had one, in the ground truth of that moment. Two different
objects: one object's symbol went to the other. The *first* object, not the latest: an anchor that
took another object's views before the merge refers to that one by then (the living room's
bicycle's anchor did), and the first is also what the planner was first told the symbol means.
The footprint, not the centre: a bicycle seen only end-on is anchored at its near end, 0.8 m from
its centre. An anchor never near an object of its class is recorded, not judged; nor is a view
whose box takes in the centres of two objects of its class or more (a detector's box across two
books of a shelf, anchored, then forgotten into one of the two as "not an object of its own", was
judged the first book's and its merge wrong: `moved_to_the_far_room`, network, seed 0, 8 December
2026), which is no one object's view.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from merlin2_sailor_demos.report.scorecard import AnchorRecord, TrueObject
from merlin2_sailor_demos.report.truth_timeline import REFERS_DISTANCE, TruthTimeline, nearest_of_class

Size = tuple[float, float, float]

#: Sightings of each anchor kept to find the first object it was the anchor of: a few seconds' worth.
FIRST_VIEWS = 64


@dataclass(frozen=True)
class MergeRecord:
    """One anchor forgotten ``into`` another, and the objects each was first the anchor of (None: none)."""

    stamp: float
    forgotten: str
    into: str
    forgotten_refers: str | None
    into_refers: str | None
    reason: str = ""

    @property
    def wrong(self) -> bool:
        return (self.forgotten_refers is not None and self.into_refers is not None
                and self.forgotten_refers != self.into_refers)

    def problem(self) -> str:
        return (f"{self.forgotten} (the {self.forgotten_refers}'s) was merged into {self.into} (the "
                f"{self.into_refers}'s)" + (f": {self.reason}" if self.reason else ""))

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any]) -> MergeRecord:
        return cls(float(data.get("stamp", 0.0)), str(data["forgotten"]), str(data["into"]),
                   data.get("forgotten_refers"), data.get("into_refers"), str(data.get("reason", "")))


class MergeLog:
    """Each anchor's first sightings and the merges, judged at the end (:meth:`judged`) against the
    whole ground-truth timeline: read once a second, it may lag a change a view already shows."""

    def __init__(self, first_views: int = FIRST_VIEWS) -> None:
        self._first_views = first_views
        self._views: dict[str, list[tuple[AnchorRecord, float, Size | None]]] = {}
        self._forgotten: list[tuple[float, str, str, str]] = []

    def note_view(self, record: AnchorRecord, seen: float, size: Size | None = None) -> None:
        """An anchor as an anchors message showed it, last seen at ``seen``, its box of ``size`` (m; None:
        not told)."""
        views = self._views.setdefault(record.symbol, [])
        if len(views) < self._first_views and (not views or views[-1][1] != seen):
            views.append((record, seen, size))

    def note_forgotten(self, symbol: str, into: str, stamp: float, reason: str) -> None:
        """``symbol`` was forgotten as ``into``'s object at ``stamp``."""
        self._forgotten.append((stamp, symbol, into, reason))

    def judged(self, timeline: TruthTimeline) -> list[MergeRecord]:
        """Every merge, with the object each of its two anchors was first the anchor of."""
        return [MergeRecord(stamp, symbol, into, self._first_object(symbol, timeline),
                            self._first_object(into, timeline), reason)
                for stamp, symbol, into, reason in self._forgotten]

    def _first_object(self, symbol: str, timeline: TruthTimeline) -> str | None:
        seen = (object_seen(record, truth) for record, stamp, size in self._views.get(symbol, ())
                if not across_several((truth := timeline.at(stamp)), record, size))
        return next((found for found in seen if found is not None), None)


def across_several(truth: Sequence[TrueObject], anchor: AnchorRecord, size: Size | None) -> bool:
    """Whether ``anchor``'s box (of ``size``; None: unknown, never) takes in, on the floor, the
    centres of two objects of its class or more."""
    if size is None:
        return False
    inside = [obj for obj in truth if obj.class_name == anchor.class_name
              and abs(obj.position[0] - anchor.position[0]) <= size[0] / 2.0
              and abs(obj.position[1] - anchor.position[1]) <= size[1] / 2.0]
    return len(inside) >= 2


def object_seen(anchor: AnchorRecord, truth: Sequence[TrueObject], max_distance: float = REFERS_DISTANCE) -> str | None:
    """The id of the object of ``anchor``'s class whose footprint (its centre without a size) is
    nearest the anchor on the floor, within ``max_distance``; the nearer centre breaks a tie."""
    def measure(obj: TrueObject) -> tuple[float, float]:
        return _footprint_gap(anchor.position, obj), math.dist(obj.position[:2], anchor.position[:2])

    return nearest_of_class(anchor, truth, measure, max_distance)


def _footprint_gap(point: Sequence[float], obj: TrueObject) -> float:
    """How far ``point`` lies from ``obj``'s upright, axis-aligned footprint on the floor (0 inside)."""
    half = (0.0, 0.0) if obj.size is None else (obj.size[0] / 2.0, obj.size[1] / 2.0)
    dx = max(abs(point[0] - obj.position[0]) - half[0], 0.0)
    dy = max(abs(point[1] - obj.position[1]) - half[1], 0.0)
    return math.hypot(dx, dy)
