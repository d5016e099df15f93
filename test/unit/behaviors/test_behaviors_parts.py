"""Small parts of the behaviours: places, poses, settings, message conversions, and the whole
domain run by the mission runtime in process (plans with Aries, fake robot)."""

from __future__ import annotations

import math
from dataclasses import replace
from types import SimpleNamespace

import pytest

from merlin2_sailor.anchoring.anchor import AnchorState
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.knowledge import GroundingConfig, PddlObject, Proposition, Provenance
from merlin2_sailor_behaviors.actions import BehaviorConfig, BehaviorError, Place, Places, Pose2D
from merlin2_sailor_behaviors.actions.robot_location import declare_robot_at, objects_at, robot_locations
from merlin2_sailor_behaviors.catalogue import SAILOR_ACTIONS

from .fake_robot import FakeRobot, make_robot


def test_places_come_from_the_grounding_map_with_regions_at_their_centres() -> None:
    config = GroundingConfig.from_mapping({"map": {
        "waypoints": [{"name": "kitchen", "x": 4.0, "y": 1.0}, {"name": "hall", "x": 0.0, "y": 0.0}],
        "regions": [{"name": "garage", "x_min": 1.0, "y_min": -1.0, "x_max": 3.0, "y_max": 1.0}]}})
    places = Places.from_grounding(config)
    assert places.get("garage") == Place("garage", 2.0, 0.0, None, is_waypoint=False)
    assert places.waypoint_names() == ("kitchen", "hall")
    assert places.nearest_waypoint(3.0, 0.5) == "kitchen"
    assert places.nearest_waypoint(math.nan, 0.0) is None
    with pytest.raises(BehaviorError, match="unknown place 'attic'.*'garage'"):
        places.get("attic")


def test_a_waypoint_heading_from_the_map_is_kept_and_used_on_arrival() -> None:
    config = SimpleNamespace(waypoints=[SimpleNamespace(name="dock", x=1.0, y=2.0, yaw=1.5)], regions=[])
    assert Places.from_grounding(config).get("dock").yaw == 1.5  # type: ignore[arg-type]
    robot = make_robot()
    robot.context = replace(robot.context, places=Places([Place("a", 0.0, 0.0), Place("b", 2.0, 0.0, yaw=-1.0)]))
    machine = SAILOR_ACTIONS["navigation"].make_state_machine(robot.context)
    assert machine(SAILOR_ACTIONS["navigation"].blackboard_for(("a", "b"))) == "succeeded"
    assert robot.navigation.goals[0].yaw == -1.0


def test_a_search_tour_always_drives_to_the_nearest_stop_not_yet_visited() -> None:
    places = Places([Place("a", 0, 0), Place("b", 2, 0), Place("c", 5, 0), Place("d", 2, 3)])
    assert places.tour("c", places.waypoint_names()) == ["c", "b", "a", "d"]
    assert places.waypoints_by_distance(2.1, 2.0) == ["d", "b", "a", "c"]


def test_poses_refuse_what_is_not_a_number_and_turn_and_face() -> None:
    with pytest.raises(BehaviorError, match="finite"):
        Pose2D(math.nan, 0.0)
    pose = Pose2D(1.0, 1.0, 0.0)
    assert pose.facing(1.0, 3.0).yaw == pytest.approx(math.pi / 2)
    assert pose.facing(1.0, 1.0) is pose
    assert pose.turned(3 * math.pi / 2).yaw == pytest.approx(-math.pi / 2)
    assert pose.turned(math.pi / 2).ahead(2.0) == pytest.approx((1.0, 3.0))


@pytest.mark.parametrize("settings", [{"look_around_turns": 1}, {"look_dwell": -1.0}, {"poll_period": 0.0},
                                      {"carry_offset": (0.0, math.inf, 0.0)}, {"approach_timeout": math.nan}])
def test_bad_settings_are_configuration_errors(settings: dict) -> None:
    with pytest.raises(ConfigurationError):
        BehaviorConfig(**settings)


def test_robot_at_is_written_as_the_one_place_the_robot_is() -> None:
    robot = make_robot()
    robot.store.propositions.save(Proposition("robot_at", ("a",)))
    robot.store.propositions.save(Proposition("robot_at", ("b",)))
    declare_robot_at(robot.store, "c")
    assert robot_locations(robot.store) == ("c",)
    fact = robot.store.propositions.get(("robot_at", ("c",), False))
    assert fact is not None and fact.provenance is Provenance.DECLARED
    robot.store.objects.save(PddlObject("cup_1", "cup"))
    robot.store.propositions.save(Proposition("object_at", ("cup_1", "c"), provenance=Provenance.PERCEIVED))
    assert objects_at(robot.store, "c") == ("cup_1",) and objects_at(robot.store, "a") == ()


def test_the_ros_conversions_of_poses_and_anchors() -> None:
    from merlin2_sailor_behaviors.ros.conversions import anchor_report, planar_pose, pose_stamped
    from merlin2_sailor_interfaces.msg import Anchor

    message = pose_stamped(Pose2D(1.0, -2.0, 2.5), "map")
    assert message.header.frame_id == "map"
    back = planar_pose(message)
    assert (back.x, back.y, back.yaw) == pytest.approx((1.0, -2.0, 2.5))
    message.pose.orientation.w = message.pose.orientation.z = 0.0
    with pytest.raises(BehaviorError, match="orientation"):
        planar_pose(message)
    anchor = Anchor(symbol="cup_1", class_name="cup", state=Anchor.STATE_MISSING, times_seen=3)
    anchor.position.x, anchor.last_seen.sec, anchor.last_seen.nanosec = 1.5, 12, 500_000_000
    report = anchor_report(anchor)
    assert (report.state, report.position, report.last_seen) == (AnchorState.MISSING, (1.5, 0.0, 0.0), 12.5)
    anchor.position.y = math.nan
    with pytest.raises(BehaviorError, match="not finite"):
        anchor_report(anchor)


# --- The domain run by the mission runtime, in process ----------------------------------------

up_aries = pytest.importorskip("up_aries", reason="planning needs Aries: pip install up-aries")

from merlin2_sailor_behaviors.planning import (  # noqa: E402
    Dispatcher,
    Mission,
    MissionRunner,
    MissionStatus,
    Planner,
)


@pytest.fixture(scope="module")
def planner() -> Planner:
    return Planner()


def mission_robot() -> FakeRobot:
    robot = make_robot()
    robot.store.propositions.save(Proposition("robot_at", ("a",)))
    robot.store.objects.save(PddlObject("cup_1", "cup"))
    return robot


def run_mission(robot: FakeRobot, planner: Planner, *goals: Proposition):  # noqa: ANN201
    """A fetch mission, with the actions such a mission allows (Aries is a satisficing planner:
    given bring too, it may carry a cup around to get somewhere)."""
    behaviours = {
        name: action.make_state_machine(robot.context)
        for name, action in SAILOR_ACTIONS.items()
        if name in ("navigation", "approach_object", "find_object")
    }
    return MissionRunner(robot.store, Dispatcher(robot.store, planner, behaviours)).run(Mission(goals))


def test_a_mission_reaches_an_anchored_object_by_navigation_and_approach(planner: Planner) -> None:
    robot = mission_robot()
    robot.store.propositions.save(Proposition("object_at", ("cup_1", "b"), provenance=Provenance.PERCEIVED))
    robot.anchoring.add("cup_1", "cup", (2.2, 0.4, 0.8))
    robot.world["cup_1"] = (2.2, 0.4)
    result = run_mission(robot, planner, Proposition("robot_near", ("cup_1",)))
    assert result.status is MissionStatus.SUCCEEDED, result.reason
    steps = [str(step) for step in result.executed]
    assert steps[-1] == "approach_object(cup_1, b)" and all(step.startswith("navigation(") for step in steps[:-1])
    assert robot_locations(robot.store) == ("b",)


def test_a_mission_finds_a_missing_object_where_the_search_ends(planner: Planner) -> None:
    robot = mission_robot()
    robot.store.propositions.save(Proposition("missing", ("cup_1",), provenance=Provenance.PERCEIVED))
    robot.anchoring.add("cup_1", "cup", (0.2, 0.1, 0.8), AnchorState.MISSING)  # last seen at a
    robot.world["cup_1"] = (2.0, 2.9)  # but it is at d now
    result = run_mission(robot, planner, Proposition("robot_near", ("cup_1",)))
    assert result.status is MissionStatus.SUCCEEDED, result.reason
    steps = [str(step) for step in result.executed]  # a satisficing planner may drive somewhere first
    assert steps[-1].startswith("find_object(cup_1, ") and all(step.startswith("navigation(") for step in steps[:-1])
    assert robot_locations(robot.store) == ("d",)  # written by find_object, kept by the dispatcher
    assert robot.store.propositions.get(("robot_near", ("cup_1",), False)) is not None
