"""Does a part of a large object show a colour the whole object lacks, and does a part of another object?

Why: in the scenario suite (`moved_to_the_far_room`, network, seed 0, 7 December 2026) a part of
the hall's bicycle (0.84 m of its 1.65) was anchored before the bicycle was seen whole, and the
two anchors were never joined: besides their boxes, their colours differed by 0.20, the part
showing twice the whole bicycle's share of its tyres' black and half its frame's orange. A part
shows only some of its object's faces, so the parts rule (:mod:`~merlin2_sailor.anchoring.parts`)
holds a part beside a whole one only to showing no colour the whole one lacks
(:func:`~merlin2_sailor.anchoring.colour_evidence.part_shows_a_colour_the_whole_lacks`), where any
two anchors are held to :func:`~merlin2_sailor.anchoring.colour_evidence.anchor_colours_differ`.

This tours held-out generated houses (as ``scripts/view_extents.py`` does), keeps every whole view
(not cut, by :func:`~merlin2_sailor.anchoring.partial_view.partial_views`) of each large object,
and makes the object's *whole* anchor of its fullest views (footprint 0.9 or more of the 90th
percentile of its views', by size and side as an anchor keeps them) and a *part* anchor of each
glance at a part of it (views whose footprint is under ``PARTIAL_FOOTPRINT_SHARE`` of that, as
:func:`~merlin2_sailor.anchoring.parts.is_part` tells a part; the first ``minimum_views`` views of
a run of them less than a second apart). Each part anchor is held to its own object's whole
anchor and to every other large object's of its class in the house, by both rules; the table
says how often each rule holds them apart: own pairs wrongly, other objects' pairs rightly.
Measured on 40 houses (7 December 2026; 79 large objects seen whole and in part, 190 glances at
parts): own pairs held apart by the test of any two anchors 17 of 190 (8.9 %), by the part's test
1 (0.5 %); other objects' pairs 183 of 274 (66.8 %) and 131 (47.8 %): the evidence the part's test
gives away, where the rest of the parts rule (the box around both fitting one object, never seen
at one time) must keep two objects apart.

Run (needs darknet's photos for the houses' textures, as ``sailor evaluate`` does)::

    SAILOR_DARKNET_DATA=$(scripts/fetch_test_data.sh) .venv/bin/python scripts/part_colours.py [HOUSES]
"""

from __future__ import annotations

import math
import sys
from collections import defaultdict
from dataclasses import dataclass, field

import numpy as np

from merlin2_sailor.anchoring.anchor import view_bearing, view_scale
from merlin2_sailor.anchoring.colour_evidence import (
    ColourBySize,
    ColourEvidenceConfig,
    ColourModel,
    anchor_colours_differ,
    part_shows_a_colour_the_whole_lacks,
    with_sized_view,
    with_view,
)
from merlin2_sailor.anchoring.features import SMALL_OBJECT_EXTENT
from merlin2_sailor.anchoring.partial_view import PARTIAL_FOOTPRINT_SHARE
from merlin2_sailor_demos.identity.house_source import HouseSource
from merlin2_sailor_demos.identity.whole_views import WholeView, collect_houses, grouped_in_time, whole_views_of_house

TOUR_RATE_HZ = 3.0
#: A view of this footprint share or more is one of the object's fullest.
FULL_SHARE = 0.9
#: Seconds: part views closer than this to the last one are of one glance at the part.
ONE_GLANCE = 1.0


@dataclass(slots=True)
class ColouredAnchor:
    """What the colour rules read of an anchor (:class:`~merlin2_sailor.anchoring.colour_evidence.Coloured`)."""

    colour: ColourModel | None = None
    colour_by_size: ColourBySize | None = None
    parts_fit: np.ndarray | None = None

    def add(self, view: WholeView) -> None:
        histogram = np.asarray(view.percept.colour, dtype=np.float64)
        self.colour = with_view(self.colour, histogram)
        bearing = view_bearing(view.percept)
        self.colour_by_size = with_sized_view(self.colour_by_size, histogram, view_scale(view.percept), bearing)


@dataclass(slots=True)
class LargeObject:
    whole: ColouredAnchor = field(default_factory=ColouredAnchor)
    parts: list[ColouredAnchor] = field(default_factory=list)


def footprint(view: WholeView) -> float:
    return float(np.max(np.asarray(view.percept.size, dtype=np.float64)[:2]))


def large_objects_of_house(house: int, source: HouseSource) -> dict[str, LargeObject]:
    """Per large object ("house/id/class") of held-out house ``house``: its whole and part anchors."""
    views: dict[str, list[WholeView]] = defaultdict(list)
    for view in whole_views_of_house(house, source, TOUR_RATE_HZ):
        if view.percept.colour is not None and math.isfinite(view_scale(view.percept)):
            views[view.key].append(view)
    objects: dict[str, LargeObject] = {}
    minimum_views = ColourEvidenceConfig().minimum_views
    for key, seen in views.items():
        whole_footprint = float(np.percentile([footprint(view) for view in seen], 90))
        if whole_footprint <= SMALL_OBJECT_EXTENT:
            continue
        found = LargeObject()
        for view in seen:
            if footprint(view) >= FULL_SHARE * whole_footprint:
                found.whole.add(view)
        part_views = [view for view in seen if footprint(view) < PARTIAL_FOOTPRINT_SHARE * whole_footprint]
        for glance in grouped_in_time(part_views, ONE_GLANCE, since_first=False):
            part = ColouredAnchor()
            for view in glance[:minimum_views]:
                part.add(view)
            found.parts.append(part)
        if found.whole.colour is not None and found.parts:
            objects[key] = found
    return objects


@dataclass(slots=True)
class Tally:
    pairs: int = 0
    differ: int = 0
    lacks: int = 0

    def add(self, part: ColouredAnchor, whole: ColouredAnchor, config: ColourEvidenceConfig) -> None:
        self.pairs += 1
        self.differ += anchor_colours_differ(part, whole, config)
        self.lacks += part_shows_a_colour_the_whole_lacks(part, whole, config)

    def row(self, label: str) -> str:
        def share(count: int) -> str:
            return f"{count} ({100.0 * count / max(self.pairs, 1):.1f} %)"
        return f"| {label} | {self.pairs} | {share(self.differ)} | {share(self.lacks)} |"


def main(houses: int) -> int:
    config = ColourEvidenceConfig()
    objects = collect_houses(houses, large_objects_of_house, "large objects")
    own, others = Tally(), Tally()
    for name, found in objects.items():
        house, _, class_name = name.split("/")
        for part in found.parts:
            own.add(part, found.whole, config)
            for other_name, other in objects.items():
                other_house, _, other_class = other_name.split("/")
                if other_name != name and other_house == house and other_class == class_name:
                    others.add(part, other.whole, config)
    print(f"{len(objects)} large objects seen both whole and in part, "
          f"{sum(len(found.parts) for found in objects.values())} glances at parts")
    print("| part anchor held to | pairs | colours differ (any two anchors) | part shows a colour the whole lacks |")
    print("| --- | --- | --- | --- |")
    print(own.row("its own object seen whole"))
    print(others.row("another object of its class seen whole"))
    return 0


if __name__ == "__main__":
    sys.exit(main(int(sys.argv[1]) if len(sys.argv) > 1 else 20))
