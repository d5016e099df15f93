"""A MERLIN2 mission of goals named on the command line, over what SAILOR anchored.

``python -m merlin2_sailor_behaviors.merlin2.mission 'explored(kitchen)' 'robot_at(hall)'``

Built on MERLIN2's own mission base (``merlin2_mission.Merlin2MissionNode``, a node under
``/merlin2``): the goals become KANT goal propositions, MERLIN2's executor generates the PDDL from
its knowledge base (SAILOR's anchors and facts included), plans, and dispatches the plan to the
actions (SAILOR's, run by ``merlin2_sailor_behaviors.merlin2.run``). The mission

* never resets the knowledge base (MERLIN2's default wipes every object and fact, the anchors
  with them);
* names goals by their objects' names; each predicate and object is looked up in KANT (waiting
  ``--wait`` seconds for them to appear), and one that is not there is a clear error before
  anything runs;
* declares ``robot_at(<waypoint nearest the robot>)`` (or ``--start``) when the knowledge base
  says nowhere, as the ``behaviors`` node does;
* waits for KANT's node (up to ``--wait``) before touching KANT's DAOs, which wait without one;
* waits for MERLIN2 with a deadline (MERLIN2's goal dispatcher waits forever): past it, the
  executor's goal is cancelled and the mission fails.

Exit status: 0 when MERLIN2 reports the goals achieved, 1 when it does not, 2 when the mission
cannot start. MERLIN2's dispatcher writes an action's effects even after the action failed, so
the knowledge base may hold a failed step's claim; the exit status is MERLIN2's own verdict.
"""

from __future__ import annotations

import argparse
import importlib
import re
import sys
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cache
from typing import Any, TypeVar

from rclpy.utilities import remove_ros_args

from merlin2_sailor.errors import DependencyError, KnowledgeError, SailorError
from merlin2_sailor.knowledge.grounding import GroundingConfig
from merlin2_sailor.knowledge.store import KnowledgeBase
from merlin2_sailor.resources import config_path
from merlin2_sailor_behaviors.actions.places import Places
from merlin2_sailor_behaviors.actions.robot_location import declare_robot_at, robot_locations
from merlin2_sailor_behaviors.merlin2.kant import KANT_LOCATION, wait_for_kant

MISSION_MODULE = "merlin2_mission"
NODE_NAME = "sailor_mission_node"
DEFAULT_TIMEOUT_SECONDS = 600.0
POSE_TIMEOUT_SECONDS = 10.0
ROBOT_POSE_TOPIC = "/robot_pose"
"""Absolute: MERLIN2's nodes live in /merlin2, the robot's pose does not."""
CANCEL_SECONDS = 10.0
DEFAULT_WAIT_SECONDS = 60.0
KNOWLEDGE_POLL_SECONDS = 0.5
KANT_EXCHANGE_SECONDS = 5.0
"""How long one exchange with KANT's node may take before it is asked again."""
T = TypeVar("T")
GOAL_PATTERN = re.compile(r"^\s*([A-Za-z][\w-]*)\s*\(\s*([^()]*)\)\s*$")


class MissionError(SailorError):
    """The mission cannot start: a goal names something the knowledge base does not hold."""


@dataclass(frozen=True)
class Goal:
    """A goal as written: ``robot_near(cup_1)``."""

    predicate: str
    objects: tuple[str, ...]

    @classmethod
    def parse(cls, text: str) -> Goal:
        match = GOAL_PATTERN.match(text)
        if match is None:
            raise MissionError(f"cannot read the goal {text!r}: write it as predicate(object, ...)")
        objects = tuple(name.strip() for name in match.group(2).split(",") if name.strip())
        return cls(match.group(1), objects)

    def __str__(self) -> str:
        return f"{self.predicate}({', '.join(self.objects)})"


def load_mission_base() -> type:
    """MERLIN2's mission node base class, imported now.

    Raises:
        DependencyError: MERLIN2's mission layer is not importable.
    """
    try:
        return importlib.import_module(MISSION_MODULE).Merlin2MissionNode
    except ImportError as error:
        raise DependencyError(
            f"a MERLIN2 mission needs MERLIN2's {MISSION_MODULE!r} ({error}); build MERLIN2 in a ROS 2 workspace "
            "and source it, or run SAILOR's own mission node ('sailor run mission') instead"
        ) from error


@cache
def goal_mission_class(base: type | None = None) -> type:
    """The mission node class on MERLIN2's base (built once)."""
    base = base if base is not None else load_mission_base()

    class GoalMissionNode(base):  # type: ignore[misc, valid-type]
        """Achieve the given goals once, through MERLIN2's planning layer."""

        def __init__(self) -> None:
            # MERLIN2 would reset the problem (the anchors with it) and run at once: neither.
            super().__init__(NODE_NAME, reset_problem=False, run_mission=False)
            self.outcome: bool | None = None

        def create_objects(self) -> list[Any]:
            return []  # the anchoring layer declares the waypoints and the anchors

        def create_propositions(self) -> list[Any]:
            return []  # robot_at is declared from where the robot is, once the node can listen

        def execute_mission(self) -> None:
            raise NotImplementedError("use run_goals, which has a deadline")

    return GoalMissionNode


def goal_dtos(store: KnowledgeBase, goals: Sequence[Goal]) -> list[Any]:
    """The goals as KANT goal propositions, each predicate and object typed as KANT holds it
    (``store`` reads KANT: a ``kant+ros`` store, whose every exchange has a deadline).

    Raises:
        MissionError: a predicate or object the knowledge base does not hold, or a wrong arity.
        KnowledgeError: KANT did not answer in time.
    """
    dto = importlib.import_module("kant_dto")
    result = []
    for goal in goals:
        predicate = store.predicates.get(goal.predicate)
        if predicate is None:
            raise MissionError(f"goal {goal}: the knowledge base has no predicate {goal.predicate!r}; "
                               "are the actions that use it registered?")
        if len(predicate.parameter_types) != len(goal.objects):
            raise MissionError(f"goal {goal}: {goal.predicate} takes {len(predicate.parameter_types)} object(s)")
        arguments = []
        for name in goal.objects:
            item = store.objects.get(name)
            if item is None:
                raise MissionError(f"goal {goal}: the knowledge base has no object {name!r} (not anchored yet?)")
            arguments.append(dto.PddlObjectDto(dto.PddlTypeDto(item.type), item.name))
        predicate_dto = dto.PddlPredicateDto(predicate.name, [dto.PddlTypeDto(t) for t in predicate.parameter_types])
        result.append(dto.PddlPropositionDto(predicate_dto, arguments, is_goal=True))
    return result


def when_known(ask: Callable[[], T], timeout: float) -> T:
    """``ask()``, asked again while it fails for something the knowledge base does not hold yet,
    until ``timeout`` seconds pass (in a launch, the actions and the anchoring node may still be
    declaring the predicates, waypoints and anchors a mission names).

    Raises:
        MissionError: still failing after ``timeout``; the message says what is missing.
    """
    deadline = time.monotonic() + timeout
    while True:
        try:
            return ask()
        except (MissionError, KnowledgeError) as error:
            if time.monotonic() >= deadline:
                raise MissionError(f"{error} (waited {timeout:g} s)") from error
        time.sleep(KNOWLEDGE_POLL_SECONDS)


def place_robot(store: KnowledgeBase, places: Places, start: str, pose_topic: str, timeout: float) -> str:
    """Where the knowledge base says the robot is; when it says nowhere, ``start`` or the waypoint
    nearest the robot's pose (``robot_pose``), declared.

    Raises:
        MissionError: no robot pose within ``timeout`` and no ``start``, or an unknown ``start``.
    """
    known = robot_locations(store)
    if known and not start:
        return known[0]
    if start:
        if start not in places.waypoint_names():
            raise MissionError(f"--start {start!r} is not a waypoint of the map ({', '.join(places.waypoint_names())})")
        declare_robot_at(store, start)
        return start
    pose = first_robot_pose(pose_topic, timeout)
    if pose is None:
        raise MissionError(f"no robot pose on {pose_topic} within {timeout:g} s and "
                           "the knowledge base does not say where the robot is; give --start WAYPOINT")
    place = places.nearest_waypoint(*pose)
    if place is None:
        raise MissionError(f"the robot at ({pose[0]:.2f}, {pose[1]:.2f}) is near none of the map's waypoints")
    declare_robot_at(store, place)
    return place


def first_robot_pose(topic: str, timeout: float) -> tuple[float, float] | None:
    """The first robot pose heard within ``timeout`` seconds.

    Heard on a short-lived node of its own, never on the mission node: that node's executor spins
    on simple_node's thread, and a subscription destroyed while that executor builds its wait set
    raises rclpy's InvalidHandle there, which ends the thread; the mission then never hears
    MERLIN2's result.
    """
    import rclpy
    from geometry_msgs.msg import PoseStamped
    from rclpy.wait_for_message import wait_for_message

    from merlin2_sailor.ros.qos import SENSOR_DATA

    listener = rclpy.create_node("sailor_mission_pose_listener")
    try:
        heard, message = wait_for_message(PoseStamped, listener, topic, qos_profile=SENSOR_DATA,
                                          time_to_wait=timeout)
    finally:
        listener.destroy_node()
    return (message.pose.position.x, message.pose.position.y) if heard else None


def run_goals(node: Any, goals: list[Any], timeout: float) -> bool | None:
    """MERLIN2 achieves the goals (True), fails them (False), or has not answered within
    ``timeout`` seconds (None: its goal is then cancelled)."""
    verdict: list[bool] = []
    worker = threading.Thread(target=lambda: verdict.append(bool(node.execute_goals(goals))),
                              name="mission-goals", daemon=True)
    worker.start()
    worker.join(timeout)
    if worker.is_alive():
        node.cancel_goals()
        worker.join(CANCEL_SECONDS)
        return None
    return verdict[0] if verdict else False


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("goals", nargs="+", help="goals, e.g. 'robot_near(cup_1)' 'explored(kitchen)'")
    parser.add_argument("--grounding", default="", help="grounding YAML with the map (default: config/grounding.yaml)")
    parser.add_argument("--start", default="", help="waypoint the robot stands at, when the knowledge base says "
                                                    "nowhere (default: the one nearest its pose)")
    parser.add_argument("--robot-pose-topic", default=ROBOT_POSE_TOPIC, metavar="TOPIC",
                        help="PoseStamped topic with the robot's pose on the map (default: %(default)s)")
    parser.add_argument("--wait", type=float, default=DEFAULT_WAIT_SECONDS, metavar="SECONDS",
                        help="how long to wait for the knowledge base to hold what the goals name "
                             "(default: %(default)s)")
    parser.add_argument("--timeout", type=float, default=DEFAULT_TIMEOUT_SECONDS, metavar="SECONDS",
                        help="how long MERLIN2 may take to achieve the goals (default: %(default)s)")
    arguments = [sys.argv[0], *(sys.argv[1:] if argv is None else argv)]
    options = parser.parse_args(remove_ros_args(arguments)[1:])  # --ros-args ... are ROS's
    try:
        goals = [Goal.parse(text) for text in options.goals]
        places = Places.from_grounding(GroundingConfig.from_yaml(config_path(options.grounding, "grounding.yaml")))
        node_class = goal_mission_class()
    except SailorError as error:
        print(f"cannot start: {error}", file=sys.stderr)
        return 2

    import rclpy

    from merlin2_sailor.ros.stores import open_store
    from merlin2_sailor_behaviors.merlin2.node_threads import let_node_threads_end, ros_shutdown_ends_node_threads

    rclpy.init(args=arguments)
    node = None
    try:
        node = node_class()
        logger = node.get_logger()
        started = time.monotonic()
        wait_for_kant(options.wait)  # KANT's DAOs would wait for it without a deadline
        logger.info(f"KANT answers ({time.monotonic() - started:.1f} s)")
        # What the mission reads and declares goes through the kant+ros store, whose every exchange
        # has a deadline: a KANT DAO made just now can lose its first answer to a discovery race
        # and then waits forever.
        # Each attempt opens the store afresh: an exchange that timed out may leave its client stuck.
        def with_kant(ask: Callable[[KnowledgeBase], T]) -> Callable[[], T]:
            def attempt() -> T:
                with open_store(KANT_LOCATION, timeout=KANT_EXCHANGE_SECONDS) as store:
                    return ask(store)
            return attempt

        dtos = when_known(with_kant(lambda store: goal_dtos(store, goals)), options.wait)
        logger.info(f"KANT holds what the goals name ({time.monotonic() - started:.1f} s)")
        place = when_known(with_kant(lambda store: place_robot(
            store, places, options.start, options.robot_pose_topic, POSE_TIMEOUT_SECONDS)), options.wait)
        logger.info(f"the robot is at {place} ({time.monotonic() - started:.1f} s); goals: "
                    f"{', '.join(map(str, goals))}")
        outcome = run_goals(node, dtos, options.timeout)
        if outcome is None:
            logger.error(f"MERLIN2 did not achieve the goals within {options.timeout:g} s; cancelled")
            return 1
        result = node.goal_dispatcher.get_result()
        if not outcome:
            stages = {stage: getattr(result, stage, False) for stage in ("generate_pddl", "generate_plan",
                                                                          "dispatch_plan")}
            logger.error(f"MERLIN2 did not achieve {', '.join(map(str, goals))} (stages done: {stages})")
            return 1
        logger.info(f"MERLIN2 achieved {', '.join(map(str, goals))}")
        return 0
    except SailorError as error:
        print(f"cannot start: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        if node is not None:
            node.cancel_goals()
        return 130
    finally:
        with ros_shutdown_ends_node_threads():
            if node is not None:
                node.destroy_node()
            rclpy.try_shutdown()
            if node is not None:
                let_node_threads_end([node])


if __name__ == "__main__":
    raise SystemExit(main())
