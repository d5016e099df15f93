"""Was an anchor merged into another object's symbol? Every merge the anchoring layer made, judged.

A scorecard that judges only the target's claim misses a neighbour's symbol forgotten into another
object's: the other bicycle's anchor taken for the wheeled one's "stand-in" left the planner one
bicycle short and no claim wrong (`bicycle_wheeled_beside_another`, network, seed 1, 7 December
2026). So the demo notes every FORGOTTEN event that names the anchor it was taken for
(``details["into"]``: merges, duplicates, parts joined) with the object each of the two anchors
referred to just then, each by its own latest sighting in the ground truth of that moment
(:func:`.truth_timeline.refers_to`): a merge of two anchors that referred to two different objects
gave one object's symbol to the other. A merge where either referred to no object (an anchor placed
more than the scorecard's association distance from anything of its class) is recorded, not judged.

The kept anchor's view is the latest that arrived before the event; the anchoring node publishes a
frame's events before its anchors, so that is the view from before the merge. Should the anchors
come first, the kept anchor's view is the merged one's and the merge is judged right: a merge can be
missed, never blamed wrongly.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass
from typing import Any

from merlin2_sailor_demos.report.scorecard import AnchorRecord
from merlin2_sailor_demos.report.truth_timeline import TruthTimeline, refers_to


@dataclass(frozen=True)
class MergeRecord:
    """One anchor forgotten ``into`` another, and the objects each referred to then (None: none)."""

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
        return (f"{self.forgotten} (the {self.forgotten_refers}) was merged into {self.into} (the "
                f"{self.into_refers})" + (f": {self.reason}" if self.reason else ""))

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any]) -> MergeRecord:
        return cls(float(data.get("stamp", 0.0)), str(data["forgotten"]), str(data["into"]),
                   data.get("forgotten_refers"), data.get("into_refers"), str(data.get("reason", "")))


class MergeLog:
    """The latest view of every anchor, and the merges judged from them as their events arrive."""

    def __init__(self) -> None:
        self._views: dict[str, tuple[AnchorRecord, float]] = {}
        self.merges: list[MergeRecord] = []

    def note_view(self, record: AnchorRecord, seen: float) -> None:
        """An anchor as the latest anchors message showed it, last seen at ``seen``."""
        self._views[record.symbol] = (record, seen)

    def note_forgotten(self, symbol: str, into: str, stamp: float, reason: str, timeline: TruthTimeline) -> None:
        """``symbol`` was forgotten as ``into``'s object at ``stamp``."""
        self.merges.append(MergeRecord(stamp, symbol, into, self._refers(symbol, timeline),
                                       self._refers(into, timeline), reason))

    def as_dicts(self) -> list[dict[str, Any]]:
        return [asdict(merge) for merge in self.merges]

    def _refers(self, symbol: str, timeline: TruthTimeline) -> str | None:
        view = self._views.get(symbol)
        return refers_to(view[0], view[1], timeline) if view is not None else None
