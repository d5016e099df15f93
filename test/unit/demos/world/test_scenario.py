"""Scenario events fire on their triggers, and only while the camera cannot see them happen."""

from __future__ import annotations

import math

import numpy as np
import pytest

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor_demos.world.geometry import Pose2D
from merlin2_sailor_demos.world.scenario import Progress, Trigger
from merlin2_sailor_demos.world.world import NavigationState, World
from merlin2_sailor_demos.world.world_file import WorldDescription

from .worlds import mug, room_mapping, room_world


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


def test_a_watched_event_waits_until_the_camera_sees_the_object_and_its_destination() -> None:
    scenario = [{"name": "shown", "watched": True, "when": {"after_seconds": 1.0},
                 "move": {"object": "a", "to": [3.5, 1.5]}}]
    world = World(room_world(objects=[mug("a", 3.5, 2.0)], size=(8.0, 4.0), start=(1.0, 2.0, math.pi),
                             scenario=scenario))
    assert not world.in_view(world.object("a").box)
    world.step(2.0)
    assert not world.scenario.fired  # due, but behind the camera
    world.true_pose = Pose2D(1.0, 2.0, 0.0)
    assert [event.name for event in world.step(0.1)] == ["shown"]
    assert np.allclose(world.object("a").position[:2], (3.5, 1.5))


def test_a_move_with_a_speed_glides_there_and_fires_on_arrival() -> None:
    scenario = [{"name": "slide", "watched": True, "move": {"object": "a", "to": [3.5, 1.0], "speed": 0.5}}]
    world = World(room_world(objects=[mug("a", 3.5, 2.0)], size=(8.0, 4.0), scenario=scenario))
    assert world.step(0.02) == []  # started: under way, not fired
    assert [event.name for event in world.scenario.pending] == ["slide"]
    world.step(1.0)
    y = world.object("a").position[1]
    assert 1.45 < y < 1.55  # 0.5 m/s for about a second
    fired = []
    for _ in range(20):
        fired += world.step(0.1)
    assert [event.name for event in fired] == ["slide"] and world.scenario.pending == ()
    assert np.allclose(world.object("a").position[:2], (3.5, 1.0))
    assert fired[0].source == pytest.approx((3.5, 2.0, 0.15))


def test_robot_still_for_counts_the_time_since_the_robot_last_moved() -> None:
    scenario = [{"name": "later", "when": {"robot_still_for": 2.0}, "remove": {"object": "a"}}]
    world = World(room_world(objects=[mug("a", 7.5, 3.5)], size=(8.0, 4.0), start=(1.0, 2.0, math.pi),
                             scenario=scenario))
    world.navigate_to(1.0, 2.0, math.pi - 1.0)  # a turn in place
    while world.navigation.state is NavigationState.ACTIVE:
        world.step(0.1)
        assert world.progress().still_for < 0.2
    assert not world.scenario.fired
    world.step(1.5)
    assert not world.scenario.fired
    world.step(0.6)
    assert [event.name for event in world.scenario.fired] == ["later"]


def test_after_event_counts_only_the_visits_since_that_event_fired() -> None:
    mapping = room_mapping(objects=[mug("a", 7.5, 0.5)], size=(8.0, 4.0), start=(1.0, 2.0, math.pi), scenario=[
        {"name": "first", "when": {"after_visiting": ["far"]}, "move": {"object": "a", "to": [7.5, 3.5]}},
        {"name": "second", "when": {"after_event": "first", "after_visiting": ["start"]},
         "move": {"object": "a", "to": [7.5, 0.5]}},
    ])
    mapping["house"]["waypoints"].append({"name": "far", "x": 6.0, "y": 2.0, "yaw": math.pi})
    world = World(WorldDescription.from_mapping(mapping, "test room"))

    def go(x: float, y: float) -> None:
        world.navigate_to(x, y, math.pi)
        while world.navigation.state is NavigationState.ACTIVE:
            world.step(0.1)
        world.step(0.1)

    go(1.0, 2.0)  # "start" visited before "first" fired: it does not count for "second"
    go(6.0, 2.0)
    assert [event.name for event in world.scenario.fired] == ["first"]
    go(1.0, 2.0)
    assert [event.name for event in world.scenario.fired] == ["first", "second"]


def test_after_event_must_name_another_event() -> None:
    with pytest.raises(ConfigurationError, match="after_event names 'nothing'"):
        room_world(objects=[mug("a", 7.5, 0.5)], scenario=[
            {"name": "x", "when": {"after_event": "nothing"}, "remove": {"object": "a"}}])
    with pytest.raises(ConfigurationError, match="names must be unique"):
        room_world(objects=[mug("a", 7.5, 0.5)], scenario=[
            {"name": "x", "remove": {"object": "a"}}, {"name": "x", "remove": {"object": "a"}}])
