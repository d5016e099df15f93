"""Does a view showing less of a large object's height or length than its whole views say another colour?

Why: the scenario suite's last duplicate anchors of large objects (the dog, 6 December 2026) were
made when one whole view's colour ruled out the dog's own anchor, and in each one side had seen
less of the dog than the other without the anchoring layer knowing it: the anchor's first views
0.36 m tall against the dog's 0.52 m, or 0.33 m long against 0.56 m; or the ruling view 0.40 m
tall against 0.52 m, its lower part hidden behind furniture. Neither is cut by the image's edge
nor by an occluder beside the box, and :func:`~merlin2_sailor.anchoring.partial_view.smaller_than_known`
asks only the footprint, and only of a view smaller than its anchor.

This tours held-out generated houses (:mod:`colour_views_by_size`'s tours), keeps every whole view
(not cut, by :func:`~merlin2_sailor.anchoring.partial_view.partial_views`) of a large object, and
measures each view's *extent share*: the least of its height and footprint over the object's
(the 90th percentile of its whole views': what a whole view shows). Then, against the colour of
the object's fullest views (share 0.9 or more, held to those of about the view's size and side as
a single view is), how often a view is ruled out by colour
(:func:`~merlin2_sailor.anchoring.colour_evidence.sized_view_differs`), by its share; and how
often views of *another* object of the class are, by share (the evidence a rule on extent would
give away).

Run (needs darknet's photos for the houses' textures, as ``sailor evaluate`` does)::

    SAILOR_DARKNET_DATA=$(scripts/fetch_test_data.sh) .venv/bin/python scripts/view_extents.py [HOUSES]
"""

from __future__ import annotations

import math
import sys
from collections import defaultdict
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.anchoring.anchor import view_scale
from merlin2_sailor.anchoring.colour_evidence import ColourEvidenceConfig, sized_view_differs, with_sized_view
from merlin2_sailor.anchoring.features import SMALL_OBJECT_EXTENT
from merlin2_sailor_demos.identity.house_source import HouseSource
from merlin2_sailor_demos.identity.whole_views import collect_houses, whole_views_of_house

TOUR_RATE_HZ = 3.0
#: Share buckets' lower edges.
BUCKETS = (0.0, 0.5, 0.6, 0.7, 0.8, 0.9)
#: A view of this share or more is one of the object's fullest.
FULL_SHARE = 0.9


@dataclass(frozen=True, slots=True)
class ExtentView:
    histogram: np.ndarray
    scale: float
    bearing: float
    height: float
    footprint: float


def views_of_large_objects(house: int, source: HouseSource) -> dict[str, list[ExtentView]]:
    """Per large object ("house/id/class") of held-out house ``house``: its whole views."""
    views: dict[str, list[ExtentView]] = defaultdict(list)
    for view in whole_views_of_house(house, source, TOUR_RATE_HZ):
        percept, camera = view.percept, view.camera
        scale = view_scale(percept)
        if not (math.isfinite(scale) and scale > 0.0):
            continue
        size = np.asarray(percept.size, dtype=np.float64)
        bearing = math.atan2(camera[1] - percept.position[1], camera[0] - percept.position[0])
        views[view.key].append(ExtentView(np.asarray(percept.colour, dtype=np.float64), scale, bearing,
                                          float(size[2]), float(np.max(size[:2]))))
    return {name: found for name, found in views.items()
            if float(np.percentile([view.footprint for view in found], 90)) > SMALL_OBJECT_EXTENT}


def shares(views: list[ExtentView]) -> np.ndarray:
    height = float(np.percentile([view.height for view in views], 90))
    footprint = float(np.percentile([view.footprint for view in views], 90))
    return np.array([min(view.height / height, view.footprint / footprint) for view in views])


def bucket(share: float) -> float:
    return max(edge for edge in BUCKETS if share >= edge)


def main(houses: int) -> int:
    config = ColourEvidenceConfig()
    objects = collect_houses(houses, views_of_large_objects, "large objects")
    fullest = {}
    share_of = {}
    for name, views in objects.items():
        share_of[name] = shares(views)
        model = None
        for view, share in zip(views, share_of[name], strict=True):
            if share >= FULL_SHARE:
                model = with_sized_view(model, view.histogram, view.scale, view.bearing)
        fullest[name] = model
    own_tests: dict[float, int] = defaultdict(int)
    own_ruled: dict[float, int] = defaultdict(int)
    every_share: list[float] = []
    for name, views in objects.items():
        if fullest[name] is None:
            continue
        for view, share in zip(views, share_of[name], strict=True):
            every_share.append(float(share))
            if share >= FULL_SHARE:
                continue  # its own model's view: not a test
            own_tests[bucket(share)] += 1
            own_ruled[bucket(share)] += sized_view_differs(
                fullest[name], view.histogram, view.scale, config, view.bearing)
    other_tests: dict[float, int] = defaultdict(int)
    other_ruled: dict[float, int] = defaultdict(int)
    for name, views in objects.items():
        house, _, class_name = name.split("/")
        for other in objects:
            if other == name or fullest[other] is None or other.split("/")[0] != house:
                continue
            if other.split("/")[2] != class_name:
                continue
            for view, share in list(zip(views, share_of[name], strict=True))[::max(1, len(views) // 20)]:
                other_tests[bucket(share)] += 1
                other_ruled[bucket(share)] += sized_view_differs(
                    fullest[other], view.histogram, view.scale, config, view.bearing)
    print(f"{len(objects)} large objects, {len(every_share)} whole views; share of the object's extent "
          f"(least of height and footprint over their 90th percentiles):")
    points = np.percentile(every_share, [1, 5, 10, 25, 50]) if every_share else []
    print("  percentiles 1/5/10/25/50: " + ", ".join(f"{value:.2f}" for value in points))
    print("share bucket | own views tested against the fullest views | ruled out | other objects' views | ruled out")
    for edge in BUCKETS:
        own = own_tests[edge]
        other = other_tests[edge]
        print(f"  >= {edge:.1f} | {own} | {own_ruled[edge]} ({100.0 * own_ruled[edge] / max(own, 1):.1f} %) | "
              f"{other} | {other_ruled[edge]} ({100.0 * other_ruled[edge] / max(other, 1):.1f} %)")
    return 0


if __name__ == "__main__":
    sys.exit(main(int(sys.argv[1]) if len(sys.argv) > 1 else 20))
