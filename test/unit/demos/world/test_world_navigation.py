"""Navigation goals in the world: arrival, cancel, preemption, refusal of impossible goals."""

from __future__ import annotations

import math

import pytest

from merlin2_sailor.errors import InvalidInputError
from merlin2_sailor_demos.world.world import NavigationState, World


def _run(world: World, seconds: float) -> None:
    for _ in range(int(seconds / 0.1)):
        world.step(0.1)


def test_a_goal_to_another_waypoint_arrives_and_counts_the_visit(house_description) -> None:
    world = World(house_description, seed=2)
    hall = world.house.waypoint("hall").pose
    goal = world.navigate_to(hall.x, hall.y, hall.yaw)
    assert goal.plan.reachable and world.distance_remaining() > 3.0
    _run(world, 30.0)
    assert goal.state is NavigationState.ARRIVED and world.distance_remaining() == 0.0
    assert world.true_pose.distance_to(hall.x, hall.y) < 0.15
    assert world.arrivals == 1 and world.visited == {"hall"}
    assert world.house.room_at(*world.true_pose.position).name == "hall"


def test_a_cancelled_goal_brakes_and_does_not_arrive(house_description) -> None:
    world = World(house_description, seed=2)
    hall = world.house.waypoint("hall").pose
    goal = world.navigate_to(hall.x, hall.y)
    _run(world, 4.0)
    assert world.cancel_navigation(goal.id) and not world.cancel_navigation(goal.id)
    _run(world, 3.0)
    stopped = world.true_pose
    _run(world, 1.0)
    assert goal.state is NavigationState.CANCELED and world.arrivals == 0
    assert world.true_pose == stopped and world.true_pose.distance_to(hall.x, hall.y) > 1.0


def test_a_new_goal_preempts_the_running_one(house_description) -> None:
    world = World(house_description, seed=2)
    first = world.navigate_to(*world.house.waypoint("hall").pose.position)
    _run(world, 2.0)
    living = world.house.waypoint("living_room").pose
    second = world.navigate_to(living.x, living.y, living.yaw)
    assert first.state is NavigationState.PREEMPTED
    _run(world, 30.0)
    assert second.state is NavigationState.ARRIVED and world.visited == {"living_room"}


@pytest.mark.parametrize("goal, message", [
    ((math.nan, 1.0, None), "not finite"),
    ((1.0, 1.0, math.inf), "not finite"),
    ((20.0, 1.0, None), "outside the house"),
])
def test_impossible_goals_are_refused(house_description, goal, message) -> None:
    world = World(house_description)
    with pytest.raises(InvalidInputError, match=message):
        world.navigate_to(*goal)
    assert world.navigation is None


def test_a_goal_off_the_graph_is_driven_to_straight_from_the_nearest_node(house_description) -> None:
    world = World(house_description, seed=1)
    goal = world.navigate_to(9.0, 6.9)  # the middle of the bed
    assert not goal.plan.reachable
    _run(world, 40.0)
    # No arrival on the way resets the estimate: the error is dead reckoning's over the whole path
    # (about 9.5 m), a few per cent of it with this odometry's noise.
    assert goal.state is NavigationState.ARRIVED
    assert world.true_pose.distance_to(9.0, 6.9) < 0.05 * goal.plan.length, goal.plan.length
