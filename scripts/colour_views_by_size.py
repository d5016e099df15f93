"""Does one whole view's colour say "another object" when it is the same object seen at another size?

Why: duplicate anchors in the scenario suite were made when one view's colour ruled out the
object's own anchor (``nearest_anchor=... ruled out by colour``), the object then anchored anew on
its own spot. This tours held-out generated houses (``sailor evaluate``'s houses, the demo's
percept generator and ground-truth detector with instance masks; :mod:`merlin2_sailor_demos.identity.tour`),
keeps every whole view with a colour, and asks, for each return to an object after
``absence`` seconds or more (when one view may rule its anchor out):

- how often the return's first view (and its first two) differs from the anchor's colour, held
  to all of the anchor's views and to its views of about the view's size only
  (``comparable_size``); and by how much the view's size differed from the anchor's typical one;
- how often a view of *another* object of the class is ruled out (what the evidence is for), held
  to all views and to comparable ones;
- both again when a view showing clearly less of a large object than its earlier views (a part,
  :data:`~merlin2_sailor.anchoring.partial_view.PARTIAL_FOOTPRINT_SHARE` of their median extent)
  is no evidence, as the anchoring layer takes it.

Run (needs darknet's photos for the houses' textures, as ``sailor evaluate`` does)::

    SAILOR_DARKNET_DATA=$(scripts/fetch_test_data.sh) .venv/bin/python scripts/colour_views_by_size.py [HOUSES]
"""

from __future__ import annotations

import sys
from collections import defaultdict
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.anchoring.anchor import view_scale
from merlin2_sailor.anchoring.colour_evidence import ColourBySize, ColourEvidenceConfig, ColourModel, view_differs
from merlin2_sailor.anchoring.features import SMALL_OBJECT_EXTENT
from merlin2_sailor.anchoring.partial_view import PARTIAL_FOOTPRINT_SHARE
from merlin2_sailor_demos.identity.house_source import HouseSource
from merlin2_sailor_demos.identity.whole_views import collect_houses, whole_views_of_house

#: Frames per second of the tours: enough to see every object from each stop, cheap to render.
TOUR_RATE_HZ = 3.0


@dataclass(frozen=True, slots=True)
class ColourView:
    stamp: float
    histogram: np.ndarray
    size: float
    extent: float
    """The view's horizontal extent (m), the largest of its footprint's sides."""


def whole_views(house: int, source: HouseSource) -> dict[str, list[ColourView]]:
    """Every whole view with a colour of each object of held-out house ``house``, in time order."""
    views: dict[str, list[ColourView]] = defaultdict(list)
    for view in whole_views_of_house(house, source, TOUR_RATE_HZ):
        percept = view.percept
        views[view.key].append(ColourView(view.stamp, np.asarray(percept.colour, dtype=np.float64),
                                          view_scale(percept), float(np.max(percept.size[:2]))))
    return views


def model_of(views: list[ColourView]) -> ColourModel:
    model = ColourModel.of(views[0].histogram)
    for view in views[1:]:
        model.add(view.histogram)
    return model


def by_size(views: list[ColourView]) -> ColourBySize:
    model = ColourBySize()
    for view in views:
        model.add(view.histogram, view.size)
    return model


def differs(earlier: list[ColourView], view: ColourView, config: ColourEvidenceConfig, sized: bool) -> bool:
    if sized:
        return view_differs(by_size(earlier).comparable(view.size, config.comparable_size), view.histogram, config)
    return view_differs(model_of(earlier), view.histogram, config)


def a_part(earlier: list[ColourView], view: ColourView) -> bool:
    """Whether the view shows clearly less of a large object than its earlier views did."""
    known = float(np.median([other.extent for other in earlier]))
    return known > SMALL_OBJECT_EXTENT and view.extent < PARTIAL_FOOTPRINT_SHARE * known


def main(houses: int) -> int:
    config = ColourEvidenceConfig()
    objects = collect_houses(houses, whole_views, "objects")
    returns = 0
    first = {False: 0, True: 0}
    first_two = {False: 0, True: 0}
    whole_first = whole_two = 0
    size_ratios: list[float] = []
    for views in objects.values():
        for index in range(config.minimum_views, len(views)):
            if views[index].stamp - views[index - 1].stamp < config.absence:
                continue
            returns += 1
            earlier = views[:index]
            for sized in (False, True):
                one = differs(earlier, views[index], config, sized)
                first[sized] += one
                if one and index + 1 < len(views):
                    first_two[sized] += differs(earlier, views[index + 1], config, sized)
            if not a_part(earlier, views[index]) and differs(earlier, views[index], config, True):
                whole_first += 1
                if index + 1 < len(views) and not a_part(earlier, views[index + 1]):
                    whole_two += differs(earlier, views[index + 1], config, True)
            if differs(earlier, views[index], config, False):
                typical = float(np.median([view.size for view in earlier]))
                size_ratios.append(max(views[index].size / typical, typical / views[index].size))
    print(f"returns to an object after >= {config.absence:g} s: {returns}")
    print(f"  first view differs, held to all views: {first[False]}; to views of about its size "
          f"(x{config.comparable_size:g}): {first[True]}")
    print(f"  first two views differ: all views {first_two[False]}; comparable {first_two[True]}")
    print(f"  comparable, and no part of a large object: first view {whole_first}, first two {whole_two}")
    if size_ratios:
        print("  size of a differing first view against the anchor's median view (times larger or smaller): "
              + ", ".join(f"{ratio:.1f}" for ratio in sorted(size_ratios)))
    tests = ruled_all = ruled_sized = comparable = ruled_whole = 0
    for name, views in objects.items():
        house, _, class_name = name.split("/")
        if len(views) < config.minimum_views:
            continue
        whole, sized_model = model_of(views), by_size(views)
        for other, other_views in objects.items():
            if other == name or other.split("/")[0] != house or other.split("/")[2] != class_name:
                continue
            for view in other_views[::max(1, len(other_views) // 20)]:
                tests += 1
                ruled_all += view_differs(whole, view.histogram, config)
                near = sized_model.comparable(view.size, config.comparable_size)
                if near is not None and near.views >= config.minimum_views:
                    comparable += 1
                    ruled_sized += view_differs(near, view.histogram, config)
                    ruled_whole += not a_part(views, view) and view_differs(near, view.histogram, config)
    print(f"views of another object of the class: {tests}; ruled out by all views: {ruled_all} "
          f"({100.0 * ruled_all / max(tests, 1):.0f} %); with comparable views: {comparable}, of them ruled out "
          f"{ruled_sized} ({100.0 * ruled_sized / max(comparable, 1):.0f} %), of them no part of a large object "
          f"{ruled_whole} ({100.0 * ruled_whole / max(comparable, 1):.0f} %)")
    return 0


if __name__ == "__main__":
    sys.exit(main(int(sys.argv[1]) if len(sys.argv) > 1 else 20))
