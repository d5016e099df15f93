"""navigation, explore and approach_object with fake navigation and anchoring (no ROS)."""

from __future__ import annotations

import dataclasses
import math
import threading

import pytest

from merlin2_sailor.knowledge import PddlObject, Proposition, Provenance
from merlin2_sailor_behaviors.actions import REASON_KEY, WARNINGS_KEY, BehaviorConfig, Pose2D
from merlin2_sailor_behaviors.actions.places import Place, Places
from merlin2_sailor_behaviors.navigation import (
    APPROACH_OBJECT_ACTION,
    EXPLORE_ACTION,
    NAVIGATION_ACTION,
    NAVIGATION_SOURCE,
)
from merlin2_sailor_behaviors.state_machines import ABORT, CANCEL, SUCCEED, Blackboard

from .fake_robot import FAST, FakeRobot, make_robot


@pytest.fixture
def robot() -> FakeRobot:
    return make_robot()


def put(robot: FakeRobot, symbol: str, place: str, position: tuple[float, float, float]) -> None:
    """An anchored cup the knowledge base places at ``place``."""
    robot.store.objects.save(PddlObject(symbol, "cup"))
    robot.store.propositions.save(Proposition("object_at", (symbol, place), provenance=Provenance.PERCEIVED))
    robot.anchoring.add(symbol, "cup", position)


def run(robot: FakeRobot, action, *objects: str) -> tuple[str, Blackboard]:
    machine = action.make_state_machine(robot.context)
    blackboard = action.blackboard_for(objects)
    outcome = machine(blackboard)
    return outcome, blackboard


def test_navigation_announces_the_destinations_objects_on_arrival_and_looks_around(robot: FakeRobot) -> None:
    put(robot, "cup_1", "b", (2.3, 0.2, 0.8))
    put(robot, "cup_2", "b", (1.8, -0.3, 0.7))
    put(robot, "cup_3", "c", (5.0, 0.1, 0.8))  # elsewhere: not announced
    robot.store.objects.save(PddlObject("ghost_1", "cup"))  # in the knowledge base, not anchored
    robot.store.propositions.save(Proposition("object_at", ("ghost_1", "b")))

    outcome, blackboard = run(robot, NAVIGATION_ACTION, "a", "b")

    assert outcome == SUCCEED, blackboard
    expected = {(e.symbol, e.position, e.place, e.source) for e in robot.anchoring.expectations}
    assert expected == {("cup_1", (2.3, 0.2, 0.8), "b", NAVIGATION_SOURCE),
                        ("cup_2", (1.8, -0.3, 0.7), "b", NAVIGATION_SOURCE)}
    goals = robot.navigation.goals
    assert (goals[0].x, goals[0].y) == (2.0, 0.0)
    assert goals[0].yaw == pytest.approx(0.0)  # no yaw in the map: faces the way it arrives (a -> b)
    turns = goals[1:]
    assert len(turns) == FAST.look_around_turns and all((g.x, g.y) == (2.0, 0.0) for g in turns)
    yaws = [round(math.degrees(g.yaw)) % 360 for g in turns]
    assert yaws == [90, 180, 270, 0]  # a full turn in quarters, ending where it started


def test_navigation_faces_the_way_it_arrives_or_the_waypoints_own_heading(robot: FakeRobot) -> None:
    robot.navigation.pose = Pose2D(2.0, 0.0, 0.0)
    assert run(robot, NAVIGATION_ACTION, "b", "d")[0] == SUCCEED
    assert robot.navigation.goals[0].yaw == pytest.approx(math.pi / 2)  # driving north from b to d


def test_navigation_to_a_place_with_nothing_to_check_does_not_look_around(robot: FakeRobot) -> None:
    robot.navigation.pose = Pose2D(0.0, 0.0, 0.0)
    assert run(robot, NAVIGATION_ACTION, "a", "b")[0] == SUCCEED
    assert len(robot.navigation.goals) == 1 and robot.anchoring.expectations == []


def test_navigation_to_an_unknown_waypoint_aborts_with_a_clear_message(robot: FakeRobot) -> None:
    outcome, blackboard = run(robot, NAVIGATION_ACTION, "a", "attic")
    assert outcome == ABORT
    assert "unknown place 'attic'" in blackboard[REASON_KEY] and "'b'" in blackboard[REASON_KEY]
    assert robot.navigation.goals == []


def test_navigation_that_cannot_reach_its_destination_aborts(robot: FakeRobot) -> None:
    robot.navigation.unreachable.add((5.0, 0.0))
    outcome, blackboard = run(robot, NAVIGATION_ACTION, "a", "c")
    assert outcome == ABORT and "could not reach c" in blackboard[REASON_KEY] and "no path" in blackboard[REASON_KEY]


def test_navigation_still_succeeds_when_the_anchoring_layer_is_down(robot: FakeRobot) -> None:
    put(robot, "cup_1", "b", (2.3, 0.2, 0.8))
    robot.anchoring.down = True
    outcome, blackboard = run(robot, NAVIGATION_ACTION, "a", "b")
    assert outcome == SUCCEED  # the robot is there: announcing is best effort
    assert any("cannot announce" in warning for warning in blackboard[WARNINGS_KEY])


def test_cancelling_navigation_reaches_the_running_goal(robot: FakeRobot) -> None:
    robot.navigation.block = True
    machine = NAVIGATION_ACTION.make_state_machine(robot.context)
    outcomes: list[str] = []
    runner = threading.Thread(target=lambda: outcomes.append(machine(NAVIGATION_ACTION.blackboard_for(("a", "c")))))
    runner.start()
    assert robot.navigation.started.wait(5.0)
    assert machine.get_current_state() == "NAVIGATING"
    machine.cancel_state()
    runner.join(5.0)
    assert outcomes == [CANCEL] and robot.navigation.cancelled.is_set()


def test_look_around_only_dwells_with_no_turns() -> None:
    robot = make_robot(BehaviorConfig(look_around_turns=0, look_dwell=0.0))
    assert run(robot, EXPLORE_ACTION, "a")[0] == SUCCEED
    assert robot.navigation.goals == []


def test_explore_turns_through_a_full_circle_at_the_waypoint(robot: FakeRobot) -> None:
    robot.navigation.pose = Pose2D(0.1, 0.0, math.pi / 2)
    assert run(robot, EXPLORE_ACTION, "a")[0] == SUCCEED
    goals = robot.navigation.goals
    assert len(goals) == 4 and all((g.x, g.y) == (0.0, 0.0) for g in goals)
    assert [round(math.degrees(g.yaw)) % 360 for g in goals] == [180, 270, 0, 90]


def test_explore_right_after_navigation_looked_around_there_does_not_turn_again(robot: FakeRobot) -> None:
    put(robot, "cup_1", "b", (2.3, 0.2, 0.8))  # expected at b: navigation looks around on arrival
    assert run(robot, NAVIGATION_ACTION, "a", "b")[0] == SUCCEED
    goals_after_navigation = len(robot.navigation.goals)
    assert run(robot, EXPLORE_ACTION, "b")[0] == SUCCEED
    assert len(robot.navigation.goals) == goals_after_navigation  # no second 360 degrees
    assert ("info", "explore(b): looked all around here on arrival; not again") in robot.logs
    robot.navigation.pose = Pose2D(0.0, 0.0, 0.0)  # elsewhere now: a look at b says nothing about a
    assert run(robot, EXPLORE_ACTION, "a")[0] == SUCCEED
    assert len(robot.navigation.goals) == goals_after_navigation + FAST.look_around_turns


def test_an_old_look_is_not_taken_for_a_fresh_one() -> None:
    robot = make_robot(BehaviorConfig(look_around_turns=2, look_dwell=0.0, look_fresh_for=0.0))
    assert run(robot, EXPLORE_ACTION, "a")[0] == SUCCEED
    assert run(robot, EXPLORE_ACTION, "a")[0] == SUCCEED
    assert len(robot.navigation.goals) == 4  # looked twice: with 0 s fresh, every look is a new one


def test_explore_aborts_when_it_cannot_turn(robot: FakeRobot) -> None:
    robot.navigation.unreachable.add((0.0, 0.0))
    outcome, blackboard = run(robot, EXPLORE_ACTION, "a")
    assert outcome == ABORT and blackboard[REASON_KEY].startswith("looking around at a")


def test_approach_faces_the_object_and_succeeds_when_it_is_seen_again(robot: FakeRobot) -> None:
    put(robot, "cup_1", "b", (2.0, 0.8, 0.8))
    robot.navigation.pose = Pose2D(2.0, 0.0, 0.0)
    robot.world["cup_1"] = (2.0, 0.8)
    outcome, blackboard = run(robot, APPROACH_OBJECT_ACTION, "cup_1", "b")
    assert outcome == SUCCEED, blackboard
    assert robot.navigation.goals[0].yaw == pytest.approx(math.pi / 2)  # turned to face it


def test_approach_aborts_when_the_object_is_not_seen_in_time(robot: FakeRobot) -> None:
    put(robot, "cup_1", "b", (2.0, 0.8, 0.8))
    outcome, blackboard = run(robot, APPROACH_OBJECT_ACTION, "cup_1", "b")
    assert outcome == ABORT
    assert "cup_1 was not reacquired within 0.2 s" in blackboard[REASON_KEY]
    assert "confirmed, not seen again" in blackboard[REASON_KEY]


def test_approach_of_an_object_nobody_anchored_aborts(robot: FakeRobot) -> None:
    outcome, blackboard = run(robot, APPROACH_OBJECT_ACTION, "cup_9", "b")
    assert outcome == ABORT and "no anchor 'cup_9'" in blackboard[REASON_KEY]


def test_a_waypoint_is_named_to_the_navigation_and_a_region_or_a_turn_is_not(robot: FakeRobot) -> None:
    """A robot with a waypoint navigation (MERLIN2's NavigateToWp) drives to waypoints by name; a
    region's centre and the turns of a look-around are poses it has no name for."""
    put(robot, "cup_1", "b", (2.3, 0.2, 0.8))  # so the navigation looks around on arrival
    assert run(robot, NAVIGATION_ACTION, "a", "b")[0] == SUCCEED
    assert robot.navigation.waypoints[0] == "b"
    assert set(robot.navigation.waypoints[1:]) == {""} and len(robot.navigation.waypoints) > 1

    places = Places([*(robot.context.places.get(name) for name in robot.context.places.names()),
                     Place("b_area", 2.0, 1.0, is_waypoint=False)])
    region_robot = dataclasses.replace(robot, context=dataclasses.replace(robot.context, places=places))
    assert run(region_robot, NAVIGATION_ACTION, "b", "b_area")[0] == SUCCEED
    assert robot.navigation.waypoints[-1] == ""
    assert (robot.navigation.goals[-1].x, robot.navigation.goals[-1].y) == (2.0, 1.0)
