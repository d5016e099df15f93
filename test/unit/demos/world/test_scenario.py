"""Scenario events fire on their triggers, and only while the camera cannot see them happen."""

from __future__ import annotations

import math

import numpy as np
import pytest

from merlin2_sailor_demos.world.geometry import Pose2D
from merlin2_sailor_demos.world.scenario import Progress, Trigger
from merlin2_sailor_demos.world.world import NavigationState, World

from .worlds import mug, room_world


def _progress(time=0.0, arrivals=0, visited=(), room="kitchen") -> Progress:
    return Progress(time, arrivals, frozenset(visited), room)


@pytest.mark.parametrize("trigger, progress, holds", [
    (Trigger(), _progress(), True),
    (Trigger(after_seconds=10.0), _progress(time=9.9), False),
    (Trigger(after_seconds=10.0), _progress(time=10.0), True),
    (Trigger(after_arrivals=3), _progress(arrivals=2), False),
    (Trigger(after_arrivals=3), _progress(arrivals=3), True),
    (Trigger(after_visiting=("a", "b")), _progress(visited={"a"}), False),
    (Trigger(after_visiting=("a", "b")), _progress(visited={"a", "b", "c"}), True),
    (Trigger(robot_in=("hall",)), _progress(room="kitchen"), False),
    (Trigger(robot_not_in=("kitchen",)), _progress(room="kitchen"), False),
    (Trigger(robot_not_in=("kitchen",)), _progress(room="hall"), True),
    (Trigger(after_arrivals=1, robot_in=("hall",)), _progress(arrivals=1, room="hall"), True),
])
def test_a_trigger_holds_when_all_its_conditions_do(trigger, progress, holds) -> None:
    assert trigger.holds(progress) is holds


def test_a_due_move_waits_until_the_object_is_out_of_view() -> None:
    scenario = [{"name": "swap", "when": {"after_seconds": 1.0}, "move": {"object": "a", "to": [6.0, 1.0]}}]
    world = World(room_world(objects=[mug("a", 3.5, 2.0)], size=(8.0, 4.0), scenario=scenario))
    assert world.in_view(world.object("a").box)
    world.step(2.0)
    assert not world.scenario.fired and np.allclose(world.object("a").position[:2], (3.5, 2.0))
    world.true_pose = Pose2D(1.0, 2.0, math.pi)  # look at the wall behind
    fired = world.step(0.1)
    assert [event.name for event in fired] == ["swap"]
    assert np.allclose(world.object("a").position, (6.0, 1.0, 0.15))
    assert fired[0].source == pytest.approx((3.5, 2.0, 0.15)) and world.version == 1
    assert world.step(5.0) == []  # once only


def test_add_and_remove_events() -> None:
    scenario = [
        {"when": {"after_seconds": 1.0}, "remove": {"object": "a"}},
        {"when": {"after_seconds": 2.0}, "add": mug("b", 0.5, 0.5)},
    ]
    world = World(room_world(objects=[mug("a", 0.5, 3.5)], size=(8.0, 4.0), scenario=scenario))
    world.step(1.5)
    assert [item.id for item in world.objects] == []
    world.step(1.0)
    assert [item.id for item in world.objects] == ["b"]
    assert [event.action for event in world.scenario.fired] == ["remove", "add"]


def test_the_house_moves_the_red_mug_once_the_house_is_explored(house_description) -> None:
    world = World(house_description, seed=0)
    start = world.object("red_mug").position.copy()
    for name in ("living_room", "hall", "bedroom", "kitchen", "bedroom"):
        pose = world.house.waypoint(name).pose
        world.navigate_to(pose.x, pose.y, pose.yaw)
        while world.navigation.state is NavigationState.ACTIVE:
            world.step(0.2)
        if name == "bedroom" and world.scenario.fired:
            break
    assert {"kitchen", "living_room", "hall", "bedroom"} <= world.visited
    (event,) = world.scenario.fired
    moved = world.object("red_mug").position
    assert event.object_id == "red_mug" and world.house.room_at(*moved[:2]).name == "living_room"
    assert math.dist(start[:2], moved[:2]) <= 5.0  # a move the anchoring layer can follow
    assert moved[2] == pytest.approx(0.45 + 0.055)  # on the coffee table
