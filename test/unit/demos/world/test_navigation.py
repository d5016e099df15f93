"""Paths through the house: doors crossed square-on, walls and furniture kept at a distance."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from merlin2_sailor_demos.world.geometry import segment_rectangle_distance, segment_segment_distance
from merlin2_sailor_demos.world.navigation import NavigationGraph

ROBOT_RADIUS = 0.25


@pytest.fixture(scope="module")
def graph(house_description) -> NavigationGraph:
    return NavigationGraph(house_description.house, ROBOT_RADIUS)


def _clearance(house, start, end) -> float:
    walls = [segment_segment_distance(start, end, np.array(w.start), np.array(w.end)) for w in house.walls]
    furniture = [segment_rectangle_distance(start, end, p.box.minimum[:2], p.box.maximum[:2]) for p in house.furniture]
    return min(walls + furniture)


def test_every_waypoint_reaches_every_other_with_clearance(graph, house_description) -> None:
    house = house_description.house
    for first, second in itertools.permutations(house.waypoints, 2):
        plan = graph.plan((first.pose.x, first.pose.y), (second.pose.x, second.pose.y))
        assert plan.reachable, (first.name, second.name)
        points = [(first.pose.x, first.pose.y), *plan.points]
        assert points[-1] == pytest.approx((second.pose.x, second.pose.y))
        for start, end in zip(points, points[1:], strict=False):
            assert _clearance(house, np.array(start), np.array(end)) >= ROBOT_RADIUS - 1e-9


def test_the_kitchen_to_the_bedroom_goes_through_doorways(graph, house_description) -> None:
    house = house_description.house
    kitchen, bedroom = house.waypoint("kitchen").pose, house.waypoint("bedroom").pose
    plan = graph.plan((kitchen.x, kitchen.y), (bedroom.x, bedroom.y))
    assert plan.nodes[0] == "kitchen" and plan.nodes[-1] == "bedroom"
    assert {"door_2_a", "door_2_b"} & set(plan.nodes)  # the bedroom's only doorway
    straight = math.dist((kitchen.x, kitchen.y), (bedroom.x, bedroom.y))
    assert straight < plan.length < 2.0 * straight


def test_the_shortest_route_is_taken(graph, house_description) -> None:
    # From the kitchen to the living room the opening between them beats the detour through the hall.
    house = house_description.house
    kitchen, living = house.waypoint("kitchen").pose, house.waypoint("living_room").pose
    plan = graph.plan((kitchen.x, kitchen.y), (living.x, living.y))
    assert "door_3_a" in plan.nodes or plan.nodes == ()
    assert not any(node.startswith("door_0") for node in plan.nodes)


def test_a_goal_inside_furniture_ends_with_a_straight_leg_from_the_nearest_node(graph) -> None:
    plan = graph.plan((2.6, 3.2), (9.0, 6.9))  # the middle of the bed
    assert not plan.reachable
    assert plan.points[-1] == (9.0, 6.9)
    assert plan.nodes[-1] == graph.names[int(np.argmin(np.linalg.norm(graph.points - (9.0, 6.9), axis=1)))]


def test_a_clear_straight_line_needs_no_graph(graph) -> None:
    plan = graph.plan((5.25, 3.0), (5.25, 6.5))  # along the hall
    assert plan.points == ((5.25, 6.5),) and plan.reachable
