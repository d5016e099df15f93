"""How far apart are two anchors of one object that colour holds apart, against two of different objects?

Why: in the scenario suite (`large_object_wheeled_away`, network, seeds 0 and 1, 7 December 2026)
a bird known from three frames of one glance was seen again in its place 86 s later, 0.11 off in
one hue window, and anchored anew beside its own missing anchor: the colour evidence decided a
difference that one object's own views show. ``scripts/colour_one_glance.py`` found that about 1
in 20 of an object's later views is ruled out from an anchor of its first glance, whether the
anchor's views came from one glance or three moments: no threshold removes that tail without
blinding the evidence to other objects. So the reappearance rule weighs the difference instead
(:meth:`~merlin2_sailor.anchoring.identity_repair.IdentityRepair.decide_reappearances`): a
difference no larger than ``colour_minimum_difference_across_sides`` leaves it undecided.

This tours held-out generated houses at the camera's rate, makes an anchor of each object's first
glances (three consecutive frames of one moment) and one of each later *visit* (views less than a
second apart, ``absence`` seconds or more after the glance; its first 20 views) of the object and
of other objects of its class in the house, and, wherever the two anchors' colours differ
(:func:`~merlin2_sailor.anchoring.colour_evidence.anchor_colours_differ`), records by how much
(:func:`~merlin2_sailor.anchoring.colour_evidence.anchor_colour_gap`). It prints, for a few
levels, the share of each kind at or below it: own anchors a doubt at that level would spare,
other objects' anchors it would leave undecided. Measured on 20 houses (7 December 2026): one object's
pairs held apart 90 of 2,208, 54 % of them by 0.16 or less; two objects' pairs 8,479 of 10,633,
6.9 % of them by 0.16 or less.

Run (needs darknet's photos for the houses' textures, as ``sailor evaluate`` does)::

    SAILOR_DARKNET_DATA=$(scripts/fetch_test_data.sh) .venv/bin/python scripts/colour_doubt.py [HOUSES]
"""

from __future__ import annotations

import sys
from collections import defaultdict
from dataclasses import dataclass, field

from merlin2_sailor.anchoring.anchor import view_bearing, view_scale
from merlin2_sailor.anchoring.colour_evidence import (
    ColourBySize,
    ColourEvidenceConfig,
    ColourModel,
    anchor_colour_gap,
    anchor_colours_differ,
)
from merlin2_sailor_demos.identity.house_source import HouseSource
from merlin2_sailor_demos.identity.whole_views import (
    WholeView,
    collect_houses,
    grouped_in_time,
    whole_views_of_house,
)

#: Frames per second of the tours: the demo camera's rate, at which one glance gives several frames.
TOUR_RATE_HZ = 15.0
#: Seconds: views closer than this to a moment's first are of that moment (the matching table's
#: measure of when a second view comes from another moment).
ONE_GLANCE = ColourEvidenceConfig().second_view_after
#: Seconds: views closer than this to the last one are of one visit.
ONE_VISIT = 1.0
#: Views per glance anchor (as many as make a colour known), anchors per object, views per visit's
#: anchor, visits of each other object of the class held to each glance.
GLANCE_VIEWS = ColourEvidenceConfig().minimum_views
GLANCES_PER_OBJECT = 3
VISIT_VIEWS = 20
VISITS_PER_RIVAL = 4
#: Levels at which the shares are printed.
LEVELS = (0.12, 0.14, 0.16, 0.18, 0.20)


@dataclass(slots=True)
class ColouredAnchor:
    """An anchor's colours as :func:`anchor_colours_differ` reads them."""

    colour: ColourModel
    colour_by_size: ColourBySize
    parts_fit: None = None


def anchor_of(views: list[WholeView]) -> ColouredAnchor:
    colour, by_size = ColourModel.of(views[0].percept.colour), ColourBySize()
    for view in views[1:]:
        colour.add(view.percept.colour)
    for view in views:
        by_size.add(view.percept.colour, view_scale(view.percept), view_bearing(view.percept))
    return ColouredAnchor(colour, by_size)


def views_of_house(house: int, source: HouseSource) -> dict[str, list[WholeView]]:
    views: dict[str, list[WholeView]] = defaultdict(list)
    for view in whole_views_of_house(house, source, TOUR_RATE_HZ):
        views[view.key].append(view)
    return views


@dataclass(slots=True)
class Pairs:
    """Pairs of anchors of one kind (one object's, two objects'): how many were compared, and the
    gaps of those whose colours differ."""

    compared: int = 0
    gaps: list[float] = field(default_factory=list)

    def share_within(self, level: float) -> str:
        within = sum(gap <= level for gap in self.gaps)
        return f"{within} ({100.0 * within / max(len(self.gaps), 1):.1f} %)"


def pairs_held_apart(objects: dict[str, list[WholeView]], config: ColourEvidenceConfig) -> tuple[Pairs, Pairs]:
    """(one object's pairs, two objects' pairs)."""
    own, others = Pairs(), Pairs()
    for name, views in objects.items():
        house, _, class_name = name.split("/")
        rivals = [other for key, other in objects.items()
                  if key != name and key.split("/")[0] == house and key.split("/")[2] == class_name]
        glances = [moment[:GLANCE_VIEWS] for moment in grouped_in_time(views, ONE_GLANCE, since_first=True)
                   if len(moment) >= GLANCE_VIEWS][:GLANCES_PER_OBJECT]
        for glance in glances:
            known = anchor_of(glance)
            later = [view for view in views if view.stamp - glance[-1].stamp >= config.absence]
            visits = [(own, visit) for visit in grouped_in_time(later, ONE_VISIT, since_first=False)]
            visits += [(others, visit) for rival in rivals
                       for visit in grouped_in_time(rival, ONE_VISIT, since_first=False)[:VISITS_PER_RIVAL]]
            for pairs, visit in visits:
                if len(visit) < GLANCE_VIEWS:
                    continue
                seen = anchor_of(visit[:VISIT_VIEWS])
                pairs.compared += 1
                if anchor_colours_differ(known, seen, config):
                    pairs.gaps.append(anchor_colour_gap(known, seen, config))
    return own, others


def main(houses: int) -> int:
    config = ColourEvidenceConfig()
    own, others = pairs_held_apart(collect_houses(houses, views_of_house, "objects"), config)
    print(f"tours at {TOUR_RATE_HZ:g} Hz of {houses} held-out houses; anchors of {GLANCE_VIEWS} frames of one "
          f"glance against anchors of a later visit (up to {VISIT_VIEWS} views, >= {config.absence:g} s later); "
          f"pairs whose colours differ: own object {len(own.gaps)} of {own.compared}, other objects of the class "
          f"{len(others.gaps)} of {others.compared}; the doubt level is minimum_difference_across_sides = "
          f"{config.minimum_difference_across_sides:g}")
    print("| gap at most | own pairs (spared by a doubt) | other objects' pairs (left undecided) |")
    print("| --- | --- | --- |")
    for level in LEVELS:
        print(f"| {level:.2f} | {own.share_within(level)} | {others.share_within(level)} |")
    return 0


if __name__ == "__main__":
    sys.exit(main(int(sys.argv[1]) if len(sys.argv) > 1 else 20))
