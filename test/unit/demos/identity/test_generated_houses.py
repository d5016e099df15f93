"""Generated houses: valid worlds, reproducible, with the look-alikes identity needs, never the demo's."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from merlin2_sailor.errors import DependencyError
from merlin2_sailor_demos.identity.generated_houses import (
    HouseGeneratorConfig,
    available_photos,
    generate_house,
    generated_world,
    twins_of,
)
from merlin2_sailor_demos.world.navigation import NavigationGraph
from merlin2_sailor_demos.world.world_file import load_world

from .conftest import DEMO_HOUSE

SKIMAGE_ONLY = HouseGeneratorConfig(use_darknet=False)


def test_a_house_is_a_function_of_its_generator() -> None:
    first = generate_house(np.random.default_rng(3), SKIMAGE_ONLY)
    again = generate_house(np.random.default_rng(3), SKIMAGE_ONLY)
    other = generate_house(np.random.default_rng(4), SKIMAGE_ONLY)
    assert first == again
    assert first != other


@pytest.mark.parametrize("seed", range(6))
def test_every_waypoint_is_reachable_and_every_object_stands_in_a_room(seed: int) -> None:
    description = generated_world(np.random.default_rng(seed), SKIMAGE_ONLY)
    house = description.house
    assert 2 <= len(house.rooms) <= 6 and len(house.waypoints) == len(house.rooms)
    graph = NavigationGraph(house, description.robot.radius)
    for start, goal in itertools.combinations(house.waypoints, 2):
        plan = graph.plan((start.pose.x, start.pose.y), (goal.pose.x, goal.pose.y))
        assert plan.points, f"no path from {start.name} to {goal.name}"
    for spec in description.objects:
        assert house.room_at(*spec.xy) is not None
    for first, second in itertools.combinations(description.objects, 2):  # no two objects inside each other
        gap = np.abs(np.subtract(first.xy, second.xy)) - (np.asarray(first.size[:2]) + second.size[:2]) / 2
        assert gap.max() > 0.0, (first.id, second.id)


def test_houses_hold_twins_families_rows_large_objects_and_moves() -> None:
    twins = families = rows = large = moves = 0
    for seed in range(12):
        description = generated_world(np.random.default_rng(seed), SKIMAGE_ONLY)
        twins += len(twins_of(description))
        textures = description.textures
        by_class: dict[str, list[str]] = {}
        for spec in description.objects:
            by_class.setdefault(spec.class_name, []).append(spec.texture)
        for names in by_class.values():  # same photo, another texture: a family (red, blue and green mugs)
            families += sum(1 for a, b in itertools.combinations(sorted(set(names)), 2)
                            if textures[a].photo == textures[b].photo)
        for first, second, third in itertools.combinations(description.objects, 3):
            spacing = [np.linalg.norm(np.subtract(a.xy, b.xy)) for a, b in ((first, second), (second, third))]
            if len({first.class_name, second.class_name, third.class_name}) == 1 and max(spacing) < 0.36:
                rows += 1
        large += sum(1 for spec in description.objects if max(spec.size[:2]) > 0.6)
        moves += len(description.scenario)
    assert twins >= 10 and families >= 10 and rows >= 3 and large >= 5 and moves >= 3


def test_no_generated_house_is_the_demos_house() -> None:
    demo = load_world(DEMO_HOUSE)
    demo_rooms = {(r.x_min, r.y_min, r.x_max, r.y_max) for r in demo.house.rooms}
    demo_textures = {repr(spec) for spec in demo.textures.values()}
    for seed in range(20):
        description = generated_world(np.random.default_rng(seed), SKIMAGE_ONLY)
        rooms = {(r.x_min, r.y_min, r.x_max, r.y_max) for r in description.house.rooms}
        assert rooms != demo_rooms
        assert not demo_textures & {repr(spec) for spec in description.textures.values()}


def test_missing_photos_are_an_error_not_another_house(tmp_path) -> None:
    with pytest.raises(DependencyError, match="use_darknet=False"):
        available_photos(use_darknet=True, darknet_data=str(tmp_path))
    assert all(name.startswith("skimage/") for name in available_photos(use_darknet=False))
