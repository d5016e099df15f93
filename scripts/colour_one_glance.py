"""Does an anchor whose colour comes from one glance know how much its object's colour varies?

Why: in the scenario suite (`large_object_wheeled_away`, network, seeds 0 and 1, 7 December 2026)
a bird seen once, in three consecutive frames (0.13 s), came back 86 s and 92 s later and its
first views were ruled out by colour ("0.11 in the hue window at 40 deg: 0.55 in its 3 views,
0.44 in this one"), so the bird was anchored anew on its own spot: a duplicate. A colour is
known from ``minimum_views`` whole views, and a view must differ by more than ``noise_factor``
times their spread; but three frames of one glance at the camera's 15 Hz are nearly one image,
and their spread says little of how the object's colour varies with the light and the angle.

This tours held-out generated houses (as :mod:`colour_views_by_size` does, at the camera's rate),
groups each object's whole views into *moments* (views less than ``second_view_after`` after the
moment's first are one: the matching table's own measure of when a second view comes from another
moment), and makes anchors of ``minimum_views`` views two ways: from one glance (consecutive frames
of one moment) and from as many moments (the first view of each). Each anchor is held, as the
anchoring layer holds a single view, to the first view of every later moment of its object
``absence`` seconds or more after it, and to views of other objects of its class (what the
evidence is for), wherever all its views are of about the view's size and side.
Measured on 20 houses (7 December 2026): own views ruled out 4.9 % (one glance) and 4.0 % (three
moments); other objects' views 79 % and 78 %: one glance is not why own views are ruled out.

Run (needs darknet's photos for the houses' textures, as ``sailor evaluate`` does)::

    SAILOR_DARKNET_DATA=$(scripts/fetch_test_data.sh) .venv/bin/python scripts/colour_one_glance.py [HOUSES]
"""

from __future__ import annotations

import sys
from collections import defaultdict
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.anchoring.anchor import view_bearing, view_scale
from merlin2_sailor.anchoring.colour_evidence import ColourBySize, ColourEvidenceConfig, ColourModel, view_differs
from merlin2_sailor_demos.identity.house_source import HouseSource
from merlin2_sailor_demos.identity.whole_views import collect_houses, grouped_in_time, whole_views_of_house

#: Frames per second of the tours: the demo camera's rate, at which one glance gives several frames.
TOUR_RATE_HZ = 15.0
#: Seconds: views closer than this to a moment's first are of that moment.
ONE_GLANCE = ColourEvidenceConfig().second_view_after
#: Anchors of each kind made per object (its first moments), and moments of each other object of
#: its class held to each anchor: enough for a few thousand tests, a few minutes.
ANCHORS_PER_OBJECT = 5
OTHERS_PER_ANCHOR = 4


@dataclass(frozen=True, slots=True)
class ColourView:
    stamp: float
    histogram: np.ndarray
    size: float
    bearing: float | None


def whole_views(house: int, source: HouseSource) -> dict[str, list[ColourView]]:
    """Every whole view with a colour of each object of held-out house ``house``, in time order."""
    views: dict[str, list[ColourView]] = defaultdict(list)
    for view in whole_views_of_house(house, source, TOUR_RATE_HZ):
        percept = view.percept
        views[view.key].append(ColourView(view.stamp, np.asarray(percept.colour, dtype=np.float64),
                                          view_scale(percept), view_bearing(percept)))
    return views


def moments_of(views: list[ColourView]) -> list[list[ColourView]]:
    """The views grouped into moments: a view ``ONE_GLANCE`` or more after the moment's first
    begins the next."""
    return grouped_in_time(views, ONE_GLANCE, since_first=True)


def held_to(anchor_views: list[ColourView], view: ColourView, config: ColourEvidenceConfig) -> ColourModel | None:
    """The anchor's views of about ``view``'s size and side, as one model, if all of them are
    (else None: the test would hold the view to fewer views than it means to)."""
    model = ColourBySize()
    for anchor_view in anchor_views:
        model.add(anchor_view.histogram, anchor_view.size, anchor_view.bearing)
    near = model.comparable(view.size, config.comparable_size, view.bearing, config.comparable_bearing)
    return near if near is not None and near.views == len(anchor_views) else None


def anchors_of(grouped: list[list[ColourView]], views: int) -> dict[str, list[list[ColourView]]]:
    """Anchors of ``views`` views each: from one glance (consecutive frames of one moment), and
    from as many moments (the first view of each of consecutive moments)."""
    glances = [moment[:views] for moment in grouped if len(moment) >= views]
    spread = [[moment[0] for moment in grouped[start:start + views]] for start in range(len(grouped) - views + 1)]
    return {"one glance": glances[:ANCHORS_PER_OBJECT], f"{views} moments": spread[:ANCHORS_PER_OBJECT]}


def main(houses: int) -> int:
    config = ColourEvidenceConfig()
    objects = {name: moments_of(views) for name, views in collect_houses(houses, whole_views, "objects").items()}
    own: dict[str, list[int]] = defaultdict(lambda: [0, 0])  # tests, ruled out
    others: dict[str, list[int]] = defaultdict(lambda: [0, 0])
    anchors: dict[str, int] = defaultdict(int)
    for name, grouped in objects.items():
        house, _, class_name = name.split("/")
        rivals = [moment[0] for key, other in objects.items()
                  if key != name and key.split("/")[0] == house and key.split("/")[2] == class_name
                  for moment in other[::max(1, len(other) // OTHERS_PER_ANCHOR)]]
        for kind, made in anchors_of(grouped, config.minimum_views).items():
            for anchor_views in made:
                anchors[kind] += 1
                last = anchor_views[-1].stamp
                for moment in grouped:
                    if moment[0].stamp - last < config.absence:
                        continue
                    model = held_to(anchor_views, moment[0], config)
                    if model is not None:
                        own[kind][0] += 1
                        own[kind][1] += view_differs(model, moment[0].histogram, config)
                for view in rivals:
                    model = held_to(anchor_views, view, config)
                    if model is not None:
                        others[kind][0] += 1
                        others[kind][1] += view_differs(model, view.histogram, config)
    print(f"tours at {TOUR_RATE_HZ:g} Hz of {houses} held-out houses; a moment: views within {ONE_GLANCE:g} s of "
          f"its first; anchors of {config.minimum_views} whole views; a view held to them only where all "
          f"{config.minimum_views} are of about its size and side")
    print("| anchor's views from | anchors | own views >= "
          f"{config.absence:g} s later | ruled out | other objects' views | ruled out |")
    print("| --- | --- | --- | --- | --- | --- |")
    for kind in anchors:
        tests, ruled = own[kind]
        rival_tests, rival_ruled = others[kind]
        print(f"| {kind} | {anchors[kind]} | {tests} | {ruled} ({100.0 * ruled / max(tests, 1):.1f} %) | "
              f"{rival_tests} | {rival_ruled} ({100.0 * rival_ruled / max(rival_tests, 1):.0f} %) |")
    return 0


if __name__ == "__main__":
    sys.exit(main(int(sys.argv[1]) if len(sys.argv) > 1 else 20))
