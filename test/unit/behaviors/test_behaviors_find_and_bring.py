"""find_object and bring with fake navigation, anchoring and gripper (no ROS)."""

from __future__ import annotations

import math
import threading

import pytest

from merlin2_sailor.anchoring.anchor import AnchorState
from merlin2_sailor.knowledge import PddlObject, Proposition
from merlin2_sailor_behaviors.actions import (
    CLASS_NAME_KEY,
    FOUND_AT_KEY,
    FOUND_SYMBOL_KEY,
    REASON_KEY,
    WARNINGS_KEY,
    BehaviorConfig,
    GraspResult,
    Pose2D,
)
from merlin2_sailor_behaviors.actions.robot_location import robot_locations
from merlin2_sailor_behaviors.find_object import FIND_OBJECT_ACTION, FIND_SOURCE, find_object_state_machine
from merlin2_sailor_behaviors.manipulation import BRING_ACTION, BRING_SOURCE
from merlin2_sailor_behaviors.state_machines import ABORT, CANCEL, SUCCEED, Blackboard

from .fake_robot import FAST, WAYPOINTS, FakeRobot, make_robot


@pytest.fixture
def robot() -> FakeRobot:
    robot = make_robot()
    robot.store.objects.save(PddlObject("cup_1", "cup"))
    robot.store.propositions.save(Proposition("missing", ("cup_1",)))
    robot.store.propositions.save(Proposition("robot_at", ("a",)))
    robot.anchoring.add("cup_1", "cup", (2.2, 0.1, 0.8), AnchorState.MISSING)  # last anchored near b
    return robot


def find(robot: FakeRobot, *objects: str) -> tuple[str, Blackboard]:
    blackboard = FIND_OBJECT_ACTION.blackboard_for(objects)
    outcome = FIND_OBJECT_ACTION.make_state_machine(robot.context)(blackboard)
    return outcome, blackboard


def stops(robot: FakeRobot) -> list[str]:
    """The waypoints the robot drove to, in order, without the turns made at each."""
    named = {xy: name for name, xy in WAYPOINTS.items()}
    visited: list[str] = []
    for position in robot.navigation.positions():
        name = named.get(position)
        if name is not None and (not visited or visited[-1] != name):
            visited.append(name)
    return visited


def test_find_goes_first_to_where_it_was_last_anchored_and_succeeds_there(robot: FakeRobot) -> None:
    robot.world["cup_1"] = (2.2, 0.1)
    outcome, blackboard = find(robot, "cup_1", "a")
    assert outcome == SUCCEED, blackboard
    assert stops(robot) == ["b"]
    assert robot.navigation.goals[0].yaw == pytest.approx(math.atan2(0.1, 0.2))  # facing its last place
    at = robot.anchoring.expectations[0]
    assert (at.kind, at.symbol, at.position, at.place, at.source) == ("at", "cup_1", (2.2, 0.1, 0.8), "b", FIND_SOURCE)
    assert len(robot.navigation.goals) == 1  # seen on arrival: the look around stopped at once
    assert blackboard[FOUND_SYMBOL_KEY] == "cup_1" and blackboard[FOUND_AT_KEY] == "b"
    assert robot_locations(robot.store) == ("b",)  # written by the behaviour, DECLARED


def test_find_searches_the_other_waypoints_nearest_first_expecting_it_at_each(robot: FakeRobot) -> None:
    robot.world["cup_1"] = (5.1, 0.0)  # really at c, the last stop of the tour
    outcome, blackboard = find(robot, "cup_1", "a")
    assert outcome == SUCCEED, blackboard
    # From b, the nearest is a (2 m), then d (from a: 3.6 m; c: 5 m), then c (from d: 4.2 m).
    assert stops(robot) == ["b", "a", "d", "c"]
    announced = [(e.kind, e.place, e.position, e.radius) for e in robot.anchoring.expectations]
    # Exactly where it was last anchored; a search around every other stop, withdrawn when empty.
    radius = robot.context.config.search_radius
    assert radius > 0
    assert announced == [
        ("at", "b", (2.2, 0.1, 0.8), 0.0), ("clear", "", (0.0, 0.0, 0.0), 0.0),
        ("at", "a", (0.0, 0.0, 0.8), radius), ("clear", "", (0.0, 0.0, 0.0), 0.0),
        ("at", "d", (2.0, 3.0, 0.8), radius), ("clear", "", (0.0, 0.0, 0.0), 0.0),
        ("at", "c", (5.0, 0.0, 0.8), radius),
    ]
    assert blackboard[FOUND_AT_KEY] == "c" and robot_locations(robot.store) == ("c",)


def test_find_that_finds_nothing_aborts_after_every_waypoint_and_returns_to_its_origin(robot: FakeRobot) -> None:
    outcome, blackboard = find(robot, "cup_1", "a")
    assert outcome == ABORT
    assert blackboard[REASON_KEY] == "cup_1 was not found at b, a, d, c"
    assert stops(robot) == ["b", "a", "d", "c", "a"]  # back where the dispatcher will say it is
    assert robot_locations(robot.store) == ("a",)  # untouched by the behaviour
    kinds = [e.kind for e in robot.anchoring.expectations]
    assert kinds.count("conclude") == 1 and kinds[-1] == "conclude"  # asked before saying "not found"


def test_find_that_finds_nothing_but_leaves_a_look_alike_in_question_ends_unable_to_tell(robot: FakeRobot) -> None:
    """Concluded with no candidate, the anchoring layer reports the sought anchor indistinguishable
    from an anchor the search could not rule out: the find says "cannot be told from", not "not
    found", from its origin."""
    robot.anchoring.left_in_question = ("cup_9",)
    outcome, blackboard = find(robot, "cup_1", "a")
    assert outcome == ABORT
    assert blackboard[REASON_KEY] == "cup_1 cannot be told from cup_9 (they look alike): its identity is unknown"
    assert stops(robot) == ["b", "a", "d", "c", "a"]
    assert FOUND_SYMBOL_KEY not in blackboard


def test_find_that_finds_nothing_but_leaves_one_look_alike_alone_in_question_goes_to_it_and_takes_it(
    robot: FakeRobot,
) -> None:
    """Concluded with no candidate, the anchoring layer reports the one anchor left in question (no
    copy of the sought one anchored) found by look alone: the search goes to it, concludes there and
    ends found, rather than "cannot be told from"."""
    x, y = WAYPOINTS["d"]
    robot.anchoring.add("cup_9", "cup", (x + 0.3, y + 0.4, 0.8))
    robot.anchoring.alone_in_question = "cup_9"
    outcome, blackboard = find(robot, "cup_1", "a")
    assert outcome == SUCCEED, blackboard
    assert stops(robot) == [*TOUR, "d"]  # every stop, then to the candidate
    kinds = [e.kind for e in robot.anchoring.expectations]
    assert kinds.count("conclude") == 2 and kinds[-1] == "conclude"
    assert blackboard[FOUND_SYMBOL_KEY] == "cup_1" and blackboard[FOUND_AT_KEY] == "d"
    assert "cup_9" not in robot.anchoring.anchors
    noted = [message for _, message in robot.logs if "cup_1 looks like cup_9" in message]
    assert len(noted) == 1 and "the only anchor the search left in question" in noted[0]


def test_find_that_finds_only_look_alikes_it_cannot_tell_apart_ends_unsuccessful_saying_so(
    robot: FakeRobot,
) -> None:
    """The anchoring layer found two mugs either of which may be cup_1: the search stops at the
    first stop where that is known and aborts naming them, instead of claiming one."""
    from dataclasses import replace

    robot.anchoring.anchors["cup_1"] = replace(robot.anchoring.anchors["cup_1"],
                                               indistinguishable_from=("cup_4", "cup_5"))
    outcome, blackboard = find(robot, "cup_1", "a")
    assert outcome == ABORT
    assert blackboard[REASON_KEY] == "cup_1 cannot be told from cup_4, cup_5 (they look alike): its identity is unknown"
    assert stops(robot) == ["b", "a"]  # searched b, then back to its origin
    assert FOUND_SYMBOL_KEY not in blackboard


def test_find_goes_on_past_a_waypoint_it_cannot_reach(robot: FakeRobot) -> None:
    robot.navigation.unreachable.add((0.0, 0.0))
    robot.world["cup_1"] = (2.0, 3.0)
    outcome, blackboard = find(robot, "cup_1", "a")
    assert outcome == SUCCEED and blackboard[FOUND_AT_KEY] == "d"
    assert any("could not reach a" in warning for warning in blackboard[WARNINGS_KEY])


def test_find_of_an_unanchored_symbol_aborts_with_a_clear_message(robot: FakeRobot) -> None:
    robot.store.objects.save(PddlObject("cup_7", "cup"))
    outcome, blackboard = find(robot, "cup_7", "a")
    assert outcome == ABORT and "no anchor 'cup_7'" in blackboard[REASON_KEY]
    assert robot.navigation.goals == []


def test_find_by_class_name_outside_pddl_takes_any_anchor_of_that_class_seen_again(robot: FakeRobot) -> None:
    robot.world["cup_1"] = (2.0, 3.2)
    blackboard = Blackboard()
    blackboard[CLASS_NAME_KEY] = "cup"
    outcome = find_object_state_machine(robot.context)(blackboard)
    assert outcome == SUCCEED, blackboard[REASON_KEY] if REASON_KEY in blackboard else ""
    assert blackboard[FOUND_SYMBOL_KEY] == "cup_1" and blackboard[FOUND_AT_KEY] == "d"
    assert robot.anchoring.expectations == []  # a class has no anchor to move


def test_cancelling_find_reaches_the_running_state(robot: FakeRobot) -> None:
    robot.navigation.block = True
    machine = FIND_OBJECT_ACTION.make_state_machine(robot.context)
    outcomes: list[str] = []
    blackboard = FIND_OBJECT_ACTION.blackboard_for(("cup_1", "a"))
    thread = threading.Thread(target=lambda: outcomes.append(machine(blackboard)))
    thread.start()
    assert robot.navigation.started.wait(5.0)
    machine.cancel_state()
    thread.join(5.0)
    assert outcomes == [CANCEL] and robot.navigation.cancelled.is_set()


@pytest.fixture
def scene() -> FakeRobot:
    robot = make_robot()
    robot.navigation.pose = Pose2D(2.0, 0.0, 0.0)
    robot.store.objects.save(PddlObject("cup_1", "cup"))
    robot.anchoring.add("cup_1", "cup", (2.5, 0.0, 0.75))
    return robot


def bring(robot: FakeRobot, *objects: str) -> tuple[str, Blackboard]:
    blackboard = BRING_ACTION.blackboard_for(objects)
    outcome = BRING_ACTION.make_state_machine(robot.context)(blackboard)
    return outcome, blackboard


def test_bring_picks_expects_carried_carries_places_and_expects_it_there(scene: FakeRobot) -> None:
    scene.navigation.on_arrival.append(
        lambda pose: scene.anchoring.see("cup_1") if scene.grasp.places else None)  # seen once put down
    outcome, blackboard = bring(scene, "cup_1", "b", "c")
    assert outcome == SUCCEED, blackboard
    assert scene.grasp.picks == [("cup", (2.5, 0.0, 0.75))]
    carried, placed = scene.anchoring.expectations
    assert (carried.kind, carried.symbol, carried.position, carried.source) == (
        "carried", "cup_1", FAST.carry_offset, BRING_SOURCE)
    assert (placed.kind, placed.place, placed.source) == ("at", "c", BRING_SOURCE)
    assert scene.grasp.places == [placed.position]
    assert placed.position == pytest.approx((5.5, 0.0, 0.75))  # half a metre ahead, facing east
    assert [(g.x, g.y) for g in scene.navigation.goals] == [(2.0, 0.0), (5.0, 0.0)]


def test_bring_warns_when_the_placed_object_is_not_seen_but_still_succeeds(scene: FakeRobot) -> None:
    outcome, blackboard = bring(scene, "cup_1", "b", "c")
    assert outcome == SUCCEED
    assert any("not seen there" in warning for warning in blackboard[WARNINGS_KEY])


def test_bring_aborts_when_the_pick_fails(scene: FakeRobot) -> None:
    scene.grasp.pick_result = GraspResult(False, "nothing to pick within 0.5 m")
    outcome, blackboard = bring(scene, "cup_1", "b", "c")
    assert outcome == ABORT and "could not pick cup_1 (cup)" in blackboard[REASON_KEY]
    assert "nothing to pick within 0.5 m" in blackboard[REASON_KEY]
    assert scene.anchoring.expectations == [] and len(scene.navigation.goals) == 1


def test_bring_aborts_when_the_anchoring_layer_is_down_before_it_starts(scene: FakeRobot) -> None:
    scene.anchoring.down = True
    outcome, blackboard = bring(scene, "cup_1", "b", "c")
    assert outcome == ABORT and "is the anchoring node running" in blackboard[REASON_KEY]
    assert scene.grasp.picks == []


def test_a_finished_search_can_run_again_with_a_fresh_blackboard() -> None:
    robot = make_robot(BehaviorConfig(look_around_turns=0, look_dwell=0.0, reacquire_timeout=0.0, poll_period=0.01))
    robot.anchoring.add("cup_1", "cup", (0.1, 0.0, 0.8), AnchorState.MISSING)
    machine = FIND_OBJECT_ACTION.make_state_machine(robot.context)
    assert machine(FIND_OBJECT_ACTION.blackboard_for(("cup_1", "a"))) == ABORT
    robot.world["cup_1"] = (0.1, 0.0)
    assert machine(FIND_OBJECT_ACTION.blackboard_for(("cup_1", "a"))) == SUCCEED


def test_find_that_sees_the_object_on_the_way_goes_to_it_and_moves_no_anchor(robot: FakeRobot) -> None:
    """The object is seen from afar while the robot drives to its first stop (a relocation merge
    re-finds it near c): the search announces it at no stop, so its anchor stays where it was seen,
    and drives to c, where it ends; never "found at" a stop it was not at (test_mission_end_to_end,
    network, 5 December 2026: the red mug, re-found in the bedroom as the robot reached the hall,
    was announced and reported at the hall)."""
    robot.world["cup_1"] = (5.1, 0.5)

    def seen_from_afar(pose: Pose2D) -> None:
        if (pose.x, pose.y) == WAYPOINTS["b"]:
            robot.anchoring.see("cup_1", (5.1, 0.5, 0.8))

    robot.navigation.on_arrival.insert(0, seen_from_afar)
    outcome, blackboard = find(robot, "cup_1", "a")
    assert outcome == SUCCEED, blackboard
    assert stops(robot) == ["b", "c"]
    assert blackboard[FOUND_AT_KEY] == "c" and robot_locations(robot.store) == ("c",)
    to_c = next(goal for goal in robot.navigation.goals if (goal.x, goal.y) == WAYPOINTS["c"])
    assert to_c.yaw == pytest.approx(math.atan2(0.5 - WAYPOINTS["c"][1], 5.1 - WAYPOINTS["c"][0]))  # facing it
    assert [e.kind for e in robot.anchoring.expectations] == []  # it was seen: nothing announced
    assert robot.anchoring.anchors["cup_1"].position[:2] == (5.1, 0.5)


TOUR = ["b", "a", "d", "c"]
"""The stops a search for cup_1 (last anchored near b) visits, in order, starting from a."""

CANDIDATE_OFFSET = (0.3, 0.4)
"""Where the look-alike found by look alone stands, from its stop's waypoint."""


def found_by_look_alone_at(robot: FakeRobot, stop: str, candidate: str = "cup_4") -> tuple[float, float, float]:
    """On the first arrival at ``stop``, the search there finds ``candidate``, which looks like
    cup_1, where the camera had never watched: the anchoring layer reports it, and merges nothing."""
    x, y = WAYPOINTS[stop]
    position = (x + CANDIDATE_OFFSET[0], y + CANDIDATE_OFFSET[1], 0.8)
    done: list[bool] = []

    def find_look_alike(pose: Pose2D) -> None:
        if not done and (pose.x, pose.y) == (x, y):
            done.append(True)
            robot.anchoring.add(candidate, "cup", position)
            robot.anchoring.report("cup_1", found_by_look_alone=candidate)

    robot.navigation.on_arrival.insert(0, find_look_alike)
    return position


def copy_turns_up_at(robot: FakeRobot, stop: str, copies: tuple[str, ...] = ("cup_4", "cup_5")) -> None:
    """On arrival at ``stop``, another copy is seen: the anchoring layer cannot tell cup_1 from them."""

    def see_copy(pose: Pose2D) -> None:
        if (pose.x, pose.y) == WAYPOINTS[stop]:
            robot.anchoring.report("cup_1", indistinguishable_from=copies)

    robot.navigation.on_arrival.insert(0, see_copy)


@pytest.mark.parametrize("stop", TOUR)
def test_find_that_finds_it_by_look_alone_searches_every_other_stop_then_takes_it_there(
    robot: FakeRobot, stop: str,
) -> None:
    """A look-alike found where the camera had never watched may be a copy that stood there all
    along: the search looks at every remaining stop, and only then, no copy seen, goes back to it,
    concludes and ends there."""
    position = found_by_look_alone_at(robot, stop)
    outcome, blackboard = find(robot, "cup_1", "a")
    assert outcome == SUCCEED, blackboard
    assert stops(robot) == (TOUR if TOUR[-1] == stop else [*TOUR, stop])  # every stop, then back to it
    kinds = [e.kind for e in robot.anchoring.expectations]
    assert kinds.count("at") == len(TOUR) and kinds[-1] == "conclude"  # concluded after every stop
    concluded = robot.anchoring.expectations[-1]
    assert (concluded.symbol, concluded.source) == ("cup_1", FIND_SOURCE)
    last = robot.navigation.goals[-1]
    assert (last.x, last.y) == WAYPOINTS[stop]
    assert last.yaw == pytest.approx(math.atan2(CANDIDATE_OFFSET[1], CANDIDATE_OFFSET[0]))  # facing it
    assert blackboard[FOUND_SYMBOL_KEY] == "cup_1" and blackboard[FOUND_AT_KEY] == stop
    assert robot_locations(robot.store) == (stop,)
    assert robot.anchoring.anchors["cup_1"].position == position and "cup_4" not in robot.anchoring.anchors
    noted = [message for _, message in robot.logs if "cup_1 looks like cup_4" in message]
    assert len(noted) == 1 and f"at {stop}" in noted[0] and "a copy may have stood there" in noted[0]


@pytest.mark.parametrize(("found_at", "copy_at"), [("b", "d"), ("b", "c"), ("a", "c")])
def test_find_that_sees_a_copy_after_a_look_alone_find_ends_unable_to_tell_and_never_concludes(
    robot: FakeRobot, found_at: str, copy_at: str,
) -> None:
    found_by_look_alone_at(robot, found_at)
    copy_turns_up_at(robot, copy_at)
    outcome, blackboard = find(robot, "cup_1", "a")
    assert outcome == ABORT
    assert blackboard[REASON_KEY] == "cup_1 cannot be told from cup_4, cup_5 (they look alike): its identity is unknown"
    searched = TOUR[:TOUR.index(copy_at) + 1]
    assert stops(robot) == [*searched, "a"]  # ends where the copy turned up, then back to its origin
    assert "conclude" not in [e.kind for e in robot.anchoring.expectations]
    assert FOUND_SYMBOL_KEY not in blackboard
    assert any("cup_1 looks like cup_4" in message for _, message in robot.logs)  # it went on past the find


def test_find_whose_conclusion_is_refused_ends_not_found_back_at_its_origin(robot: FakeRobot) -> None:
    found_by_look_alone_at(robot, "b")
    robot.anchoring.refuse_conclusions = True
    outcome, blackboard = find(robot, "cup_1", "a")
    assert outcome == ABORT
    assert blackboard[REASON_KEY] == "cup_1 was not found at b, a, d, c"
    assert stops(robot) == [*TOUR, "b", "a"]  # back to the candidate, then to its origin
    assert [e.kind for e in robot.anchoring.expectations][-1] == "conclude"
    assert FOUND_SYMBOL_KEY not in blackboard and robot_locations(robot.store) == ("a",)
    assert any("not taken for cup_1" in message for _, message in robot.logs)


def test_find_whose_conclusion_meets_a_copy_ends_unable_to_tell(robot: FakeRobot) -> None:
    """A copy anchored meanwhile (the anchoring layer refuses the conclusion and reports the
    look-alikes): the search gives up saying it cannot tell them apart."""
    found_by_look_alone_at(robot, "d")
    conclude_search = robot.anchoring.conclude_search

    def copy_then_conclude(symbol: str, source: str) -> bool:
        robot.anchoring.report("cup_1", indistinguishable_from=("cup_4", "cup_9"))
        return conclude_search(symbol, source)

    robot.anchoring.conclude_search = copy_then_conclude  # type: ignore[method-assign]
    outcome, blackboard = find(robot, "cup_1", "a")
    assert outcome == ABORT
    assert blackboard[REASON_KEY] == "cup_1 cannot be told from cup_4, cup_9 (they look alike): its identity is unknown"
    assert stops(robot) == [*TOUR, "d", "a"]
    assert FOUND_SYMBOL_KEY not in blackboard


def test_find_that_cannot_reach_the_candidate_again_ends_not_found(robot: FakeRobot) -> None:
    found_by_look_alone_at(robot, "b")

    def b_blocked_after_the_tour(pose: Pose2D) -> None:
        if (pose.x, pose.y) == WAYPOINTS["c"]:
            robot.navigation.unreachable.add(WAYPOINTS["b"])

    robot.navigation.on_arrival.append(b_blocked_after_the_tour)
    outcome, blackboard = find(robot, "cup_1", "a")
    assert outcome == ABORT and blackboard[REASON_KEY] == "cup_1 was not found at b, a, d, c"
    assert stops(robot) == [*TOUR, "b", "a"]  # tried b (no path), then back to its origin
    assert any("could not reach b" in warning for warning in blackboard[WARNINGS_KEY])
    assert "conclude" not in [e.kind for e in robot.anchoring.expectations]
