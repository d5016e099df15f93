"""The whole views of a held-out generated house's objects, as measurement scripts read them.

Scripts that measure how colour behaves across views (``scripts/colour_views_by_size.py``,
``scripts/colour_across_sides.py``, ``scripts/view_extents.py``, ``scripts/colour_one_glance.py``)
all tour ``sailor evaluate``'s held-out houses and keep the views the anchoring layer would take as
whole: with a colour, of a real object (not a false detection), and not flagged partial
(:func:`~merlin2_sailor.anchoring.partial_view.partial_views`). One tour, so they measure the same views.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Protocol, TypeVar

import numpy as np

from merlin2_sailor.anchoring.partial_view import PartialViewConfig, partial_views
from merlin2_sailor.contract.percept import Percept
from merlin2_sailor_demos.identity.house_source import HouseSource
from merlin2_sailor_demos.identity.tour import Tour, TourConfig
from merlin2_sailor_demos.world.world import World


@dataclass(frozen=True, slots=True)
class WholeView:
    """One whole view: its ``percept``, the ``stamp`` and ``camera`` position (world frame) of its
    frame, and its object's key, "house/object id/class"."""

    percept: Percept
    stamp: float
    camera: np.ndarray
    key: str


def whole_views_of_house(house: int, source: HouseSource, rate_hz: float) -> Iterator[WholeView]:
    """Every whole view with a colour of an object of held-out house ``house``, in time order, from a
    tour at ``rate_hz`` frames per second."""
    description, seed = source.house("test", house)
    world = World(description, seed=seed, segment=True, darknet_data=source.darknet_data)
    for frame in Tour(world, TourConfig(rate_hz=rate_hz)).frames():
        partial = partial_views(frame.percepts, frame.camera, PartialViewConfig())
        camera = np.asarray(frame.camera.position, dtype=np.float64)
        for percept, object_id, cut in zip(frame.percepts, frame.object_ids, partial, strict=True):
            if object_id is not None and not cut and percept.colour is not None:
                yield WholeView(percept, frame.stamp, camera, f"{house}/{object_id}/{percept.class_name}")


class Stamped(Protocol):
    stamp: float


StampedView = TypeVar("StampedView", bound=Stamped)


def grouped_in_time(views: list[StampedView], within: float, since_first: bool) -> list[list[StampedView]]:
    """Time-ordered views in groups: a view less than ``within`` seconds after the group's first
    (``since_first``: one moment, one glance) or its last view (else: one visit) joins it, a later
    one begins the next."""
    groups: list[list[StampedView]] = []
    for view in views:
        if groups and view.stamp - groups[-1][0 if since_first else -1].stamp < within:
            groups[-1].append(view)
        else:
            groups.append([view])
    return groups


Collected = TypeVar("Collected")


def collect_houses(houses: int, collect: Callable[[int, HouseSource], dict[str, Collected]],
                   what: str = "objects") -> dict[str, Collected]:
    """``collect`` of each of the first ``houses`` held-out houses, merged (their keys name the house),
    with a progress line per house on stderr: a tour of a house takes a few seconds."""
    source = HouseSource()
    collected: dict[str, Collected] = {}
    for house in range(houses):
        collected.update(collect(house, source))
        print(f"toured house {house + 1}/{houses}: {len(collected)} {what} so far", file=sys.stderr)
    return collected
