"""The simulated gripper picks the nearest object of a class within reach, carries it and places it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from merlin2_sailor_demos.world.geometry import Pose2D
from merlin2_sailor_demos.world.world import World

from .worlds import mug, room_world

TABLE = {"name": "table", "kind": "table", "center": [4.0, 3.0], "size": [1.0, 1.0, 0.8]}


def _world() -> World:
    objects = [mug("near", 2.9, 2.0, size=(0.1, 0.1, 0.1)), mug("far", 3.3, 2.0, size=(0.1, 0.1, 0.1)),
               {"id": "novel", "class": "book", "position": [2.9, 1.6], "size": [0.2, 0.05, 0.25], "texture": "mug"}]
    return World(room_world(objects=objects, furniture=[TABLE], size=(6.0, 4.0)), seed=0)


def test_picks_the_nearest_object_of_the_class() -> None:
    world = _world()
    world.true_pose = Pose2D(2.0, 2.0, 0.0)
    result = world.pick("cup", (3.0, 2.0, 0.05))
    assert result.success and result.object_id == "near"
    assert world.object("near").carried and world.version == 1
    assert "already holds 'near'" in world.pick("cup", (3.3, 2.0, 0.0)).message


def test_an_empty_class_takes_any_object() -> None:
    world = _world()
    world.true_pose = Pose2D(2.0, 2.0, 0.0)
    assert world.pick("", (2.9, 1.6, 0.0)).object_id == "novel"


@pytest.mark.parametrize("robot, class_name, target, message", [
    (Pose2D(2.0, 2.0, 0.0), "cup", (2.9, 3.5, 0.0), "no 'cup' within 0.6 m"),
    (Pose2D(0.5, 2.0, 0.0), "cup", (2.9, 2.0, 0.0), "beyond the arm's reach"),
    (Pose2D(2.0, 2.0, 0.0), "bicycle", (2.9, 2.0, 0.0), "no 'bicycle' in the world"),
    (Pose2D(2.0, 2.0, 0.0), "cup", (math.nan, 2.0, 0.0), "not a finite point"),
])
def test_refuses_what_it_cannot_reach(robot, class_name, target, message) -> None:
    world = _world()
    world.true_pose = robot
    result = world.pick(class_name, target)
    assert not result.success and message in result.message
    assert not any(item.carried for item in world.objects)


def test_a_carried_object_rides_along_unseen_and_lands_on_the_table() -> None:
    world = _world()
    world.true_pose = Pose2D(2.0, 2.0, 0.0)
    world.pick("cup", (2.9, 2.0, 0.0))
    frame = world.render()
    assert "near" not in {world.objects[seen.index].id for seen in world.visible_objects(frame)}
    world.navigate_to(3.2, 3.0)
    while world.navigation.state.value == "active":
        world.step(0.2)
    held = world.object("near")
    assert np.allclose(held.position[:2], (world.true_pose.x, world.true_pose.y))
    result = world.place((4.0, 3.0, 0.0))
    assert result.success
    assert held.position == pytest.approx((4.0, 3.0, 0.85))  # table top 0.8 + half the mug
    assert not held.carried and world.gripper.held is None


def test_place_ahead_of_the_robot_and_refusals() -> None:
    world = _world()
    assert world.place((1.0, 1.0, 0.0)).message == "the gripper is empty"
    world.true_pose = Pose2D(2.0, 2.0, 0.0)
    world.pick("cup", (2.9, 2.0, 0.0))
    assert "beyond the arm's reach" in world.place((5.5, 0.5, 0.0)).message
    world.true_pose = Pose2D(5.5, 2.0, 0.0)
    assert "outside the house" in world.place((6.5, 2.0, 0.0)).message
    world.true_pose = Pose2D(2.0, 2.0, math.pi / 2)
    assert world.place(None).success
    assert world.object("near").position[:2] == pytest.approx((2.0, 2.5))
