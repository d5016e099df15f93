"""A tour of a house: every stop visited, percepts of the real pipeline, each with its true object."""

from __future__ import annotations

import numpy as np
import pytest

from merlin2_sailor.anchoring.features import extent_slack
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor_demos.identity.generated_houses import generated_world
from merlin2_sailor_demos.identity.tour import Tour, TourConfig, object_ids_of, tour_stops
from merlin2_sailor_demos.world.world import World


@pytest.fixture(scope="module")
def frames():
    from .conftest import SMALL_HOUSES

    description = generated_world(np.random.default_rng(5), SMALL_HOUSES)
    world = World(description, seed=0, segment=True)
    tour = Tour(world, TourConfig(rate_hz=3.0, track=False))
    return world, tour, list(tour.frames())


def test_the_tour_visits_every_stop_and_comes_back(frames) -> None:
    world, tour, seen = frames
    names = [waypoint.name for waypoint in world.house.waypoints]
    assert tour.stops == names + names[-2::-1]
    stops_in_order = [frame.stop for k, frame in enumerate(seen) if k == 0 or seen[k - 1].stop != frame.stop]
    assert stops_in_order == tour.stops
    assert all(later.stamp > earlier.stamp for earlier, later in zip(seen, seen[1:], strict=False))


def test_each_percept_names_the_object_it_shows(frames) -> None:
    world, _, seen = frames
    sizes = {item.id: np.asarray(item.size) for item in world.objects}
    named = 0
    for frame in seen:
        assert len(frame.percepts) == len(frame.object_ids)
        truth = {item.id: item for item in frame.truth}  # where each object was then (objects move)
        for percept, object_id in zip(frame.percepts, frame.object_ids, strict=True):
            if object_id is None:
                continue
            named += 1
            item, size = truth[object_id], sizes[object_id]
            assert percept.class_name == item.class_name
            # the centre of what the camera saw lies on the object (partial views: on the part in view)
            reach = float(np.max(size[:2])) / 2 + float(extent_slack(size)) + 0.15
            assert np.linalg.norm(percept.position[:2] - np.asarray(item.position[:2])) < reach, object_id
    assert named > 50
    assert object_ids_of(seen) <= set(sizes)


def test_unknown_stops_are_refused() -> None:
    from .conftest import SMALL_HOUSES

    world = World(generated_world(np.random.default_rng(5), SMALL_HOUSES), seed=0)
    with pytest.raises(ConfigurationError, match="not waypoints"):
        tour_stops(world, TourConfig(stops=("attic",)))
