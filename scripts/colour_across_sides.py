"""How much does an object's colour differ between two of its sides, against two objects' colours?

Why: a merge of two anchors (a search's find, a reappearance) asks whether their colours rule out
one object, comparing each anchor's mean over its whole views. An anchor's mean is of the sides it
happened to see: a bicycle known from one end and anchored anew from its other side where it was
wheeled to differed from itself by 0.116, over the 0.1 that rules an object out, and the search for
it ended "not found" (`large_object_wheeled_away`, network, seed 2, 6 December 2026). Yet most
anchors of a house are seen from one side only: leaving out every difference without a common side
would leave 155-180 of the suite's 590 pairs of anchors of different objects whose means differ
without colour evidence. What this measures sets ``colour_minimum_difference_across_sides``, the
difference two anchors never seen from a common side must exceed (0.16: just above the p99 of one
object's sides).

This tours held-out generated houses (:mod:`colour_views_by_size`'s tours), groups each object's whole
views by the side they were seen from (sectors of 45 degrees of the bearing from the object to the
camera) and size, and for every two groups too far apart to be held to each other
(``comparable_bearing``) at about one size, each of ``minimum_views`` views or more, measures the
largest window difference (:func:`~merlin2_sailor.anchoring.colour_evidence.colour_difference`
without the noise test: the raw distance) between:

- two sides of *one* object (what a second anchor from another side differs by);
- a side of one object and a side of *another* object of its class in the house (what colour evidence
  is for).

Run (needs darknet's photos for the houses' textures, as ``sailor evaluate`` does)::

    SAILOR_DARKNET_DATA=$(scripts/fetch_test_data.sh) .venv/bin/python scripts/colour_across_sides.py [HOUSES]
"""

from __future__ import annotations

import itertools
import math
import sys
from collections import defaultdict

import numpy as np

from merlin2_sailor.anchoring.anchor import view_scale
from merlin2_sailor.anchoring.colour_evidence import (
    ColourEvidenceConfig,
    ColourModel,
    band_centre,
    bearing_gap,
    bearing_sector,
    sector_centre,
    size_band,
)
from merlin2_sailor_demos.identity.house_source import HouseSource
from merlin2_sailor_demos.identity.whole_views import collect_houses, whole_views_of_house

TOUR_RATE_HZ = 3.0

Side = tuple[int, int]
"""(size band, bearing sector) of a group of views."""


def sides_of_objects(house: int, source: HouseSource) -> dict[str, dict[Side, ColourModel]]:
    """Per object ("house/id/class") of held-out house ``house``: its whole views' colours by side."""
    sides: dict[str, dict[Side, ColourModel]] = defaultdict(dict)
    for view in whole_views_of_house(house, source, TOUR_RATE_HZ):
        percept, camera = view.percept, view.camera
        dx, dy = camera[0] - percept.position[0], camera[1] - percept.position[1]
        sector = bearing_sector(math.atan2(dy, dx))
        size = view_scale(percept)
        if sector is None or not (math.isfinite(size) and size > 0.0):
            continue
        key = (size_band(size), sector)
        groups = sides[view.key]
        if key in groups:
            groups[key].add(np.asarray(percept.colour, dtype=np.float64))
        else:
            groups[key] = ColourModel.of(np.asarray(percept.colour, dtype=np.float64))
    return sides


def apart(first: Side, second: Side, config: ColourEvidenceConfig) -> bool:
    """Two sides too far round to be held to each other, at about one size."""
    sizes = sorted((band_centre(first[0]), band_centre(second[0])))
    gap = bearing_gap(sector_centre(first[1]), sector_centre(second[1]))
    return gap > math.radians(config.comparable_bearing) and sizes[1] <= config.comparable_size * sizes[0]


def difference(first: ColourModel, second: ColourModel) -> float:
    return float(np.max(np.abs(first.mean - second.mean)))


def percentiles(values: list[float]) -> str:
    if not values:
        return "none"
    points = np.percentile(values, [1, 5, 50, 95, 99])
    return (f"{len(values)} pairs; min {min(values):.3f}, p1 {points[0]:.3f}, p5 {points[1]:.3f}, "
            f"median {points[2]:.3f}, p95 {points[3]:.3f}, p99 {points[4]:.3f}, max {max(values):.3f}")


def main(houses: int) -> int:
    config = ColourEvidenceConfig()
    objects = collect_houses(houses, sides_of_objects)
    known = {name: {side: model for side, model in sides.items() if model.views >= config.minimum_views}
             for name, sides in objects.items()}
    own: dict[str, list[float]] = defaultdict(list)
    for name, sides in known.items():
        for (side, model), (other_side, other_model) in itertools.combinations(sides.items(), 2):
            if apart(side, other_side, config):
                own[name.split("/")[2]].append(difference(model, other_model))
    others: dict[str, list[float]] = defaultdict(list)
    for (name, sides), (other, other_sides) in itertools.combinations(known.items(), 2):
        house, _, class_name = name.split("/")
        if other.split("/")[0] != house or other.split("/")[2] != class_name:
            continue
        for (side, model), (other_side, other_model) in itertools.product(sides.items(), other_sides.items()):
            if apart(side, other_side, config):
                others[class_name].append(difference(model, other_model))
    print(f"sides {config.comparable_bearing:g} degrees or more apart, at about one size, each of "
          f"{config.minimum_views}+ whole views; largest colour-window difference of their means:")
    for class_name in sorted(set(own) | set(others)):
        print(f"  {class_name}: one object's two sides: {percentiles(own[class_name])}")
        print(f"  {' ' * len(class_name)}  two objects' sides:   {percentiles(others[class_name])}")
    every_own = [value for values in own.values() for value in values]
    every_other = [value for values in others.values() for value in values]
    print(f"  all classes: one object's two sides: {percentiles(every_own)}")
    print(f"               two objects' sides:   {percentiles(every_other)}")
    for threshold in (0.10, 0.12, 0.14, 0.15, 0.16, 0.18, 0.20):
        kept = sum(value > threshold for value in every_other) / max(len(every_other), 1)
        wrong = sum(value > threshold for value in every_own) / max(len(every_own), 1)
        print(f"  over {threshold:.2f}: two objects told apart {100.0 * kept:.0f} %, one object's sides "
              f"taken for two {100.0 * wrong:.1f} %")
    return 0


if __name__ == "__main__":
    sys.exit(main(int(sys.argv[1]) if len(sys.argv) > 1 else 20))
