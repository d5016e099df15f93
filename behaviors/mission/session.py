"""A mission session: the knowledge base, the behaviours on their servers, and one mission at a time.

The mission node runs one session for its goals; the demo runs several missions (explore, then
find) through one session. Waiting is explicit and bounded: the knowledge base must answer and
the actions the behaviours register must appear, or the session says which did not.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from rclpy.node import Node

from merlin2_sailor.errors import KnowledgeError, SailorError
from merlin2_sailor.knowledge import KnowledgeBase, Proposition
from merlin2_sailor_behaviors.actions.domain import ROBOT_AT
from merlin2_sailor_behaviors.planning import (
    Dispatcher,
    DispatcherConfig,
    Mission,
    MissionResult,
    MissionRunner,
    Planner,
    PlannerConfig,
)
from merlin2_sailor_behaviors.ros.pddl_action_client import PddlActionBehaviour

Say = Callable[[str], None]


class MissionUnavailable(SailorError):
    """What a mission needs (knowledge base, actions, their servers) did not appear in time."""


@dataclass(frozen=True)
class SessionConfig:
    """Planning engine and limits; ``actions_timeout``: seconds to wait for the knowledge base to
    answer and the behaviours' actions and servers to appear; ``actions``: the actions the
    mission may use (empty: every action registered), which is also a way to keep a satisficing
    planner from wandering (an exploration has no business bringing cups around)."""

    engine: str = "aries"
    planning_timeout: float = 10.0
    max_replans: int = 3
    actions_timeout: float = 60.0
    behaviors_prefix: str = "/behaviors"
    actions: tuple[str, ...] = ()


class MissionSession:
    """Runs missions over ``store`` with the behaviours served under ``behaviors_prefix``.

    ``node`` must be spun by another thread (the mission node's executor). Only one mission runs
    at a time; :meth:`cancel` may be called from any thread.
    """

    def __init__(self, store: KnowledgeBase, node: Node, config: SessionConfig, say: Say) -> None:
        self._store = store
        self._node = node
        self._config = config
        self._say = say
        self._planner = Planner(PlannerConfig(engine=config.engine, timeout_seconds=config.planning_timeout))
        self._behaviours: dict[str, PddlActionBehaviour] = {}
        self._clients: dict[str, PddlActionBehaviour] = {}
        self._runner: MissionRunner | None = None
        self._lock = threading.Lock()
        self._canceled = threading.Event()

    def wait_until_ready(self) -> None:
        """Wait for the knowledge base, the behaviours' actions and servers, and the robot's place.

        Every plan starts from where the robot is: planning before the behaviors node has
        declared ``robot_at`` finds no plan and spends the planner's whole timeout learning so.

        Each action's client is made once and kept until :meth:`close`: destroying an rclpy
        action client while another thread spins its node can crash that executor.
        """
        deadline = time.monotonic() + self._config.actions_timeout
        last_problem = "nothing checked yet"
        while not self._canceled.is_set():
            try:
                registered = {action.name for action in self._store.actions.get_all()}
                wanted = set(self._config.actions or registered)
                unregistered = sorted(wanted - registered)
                if wanted and not unregistered:
                    for name in wanted - set(self._clients):
                        self._clients[name] = PddlActionBehaviour(
                            self._node, name, f"{self._config.behaviors_prefix.rstrip('/')}/{name}")
                    unserved = sorted(name for name in wanted if not self._clients[name].server_is_ready())
                    robot_placed = any(fact.predicate == ROBOT_AT and not fact.is_goal
                                       for fact in self._store.propositions.get_all())
                    if not unserved and not robot_placed:
                        last_problem = f"no {ROBOT_AT} fact yet: the behaviors node has not placed the robot"
                    elif not unserved:
                        self._behaviours = {name: self._clients[name] for name in sorted(wanted)}
                        self._say(f"ready: actions {', '.join(self._behaviours)}")
                        return
                    last_problem = f"no server yet for {', '.join(unserved)}"
                else:
                    last_problem = (
                        f"actions {', '.join(unregistered)} not registered yet" if unregistered
                        else "no action registered yet"
                    )
            except KnowledgeError as error:
                last_problem = f"the knowledge base does not answer ({error})"
            if time.monotonic() > deadline:
                raise MissionUnavailable(
                    f"not ready after {self._config.actions_timeout:.0f} s: {last_problem}; "
                    "is the behaviors node running with the same knowledge base?"
                )
            time.sleep(0.5)

    def run(
        self, goals: Sequence[Proposition], name: str = "mission", actions: Sequence[str] = ()
    ) -> MissionResult:
        """Run one mission to its end and word its outcome; ``actions`` narrows the ready ones."""
        behaviours = {n: b for n, b in self._behaviours.items() if not actions or n in actions}
        dispatcher = Dispatcher(
            self._store, self._planner, behaviours, DispatcherConfig(max_replans=self._config.max_replans)
        )
        runner = MissionRunner(self._store, dispatcher)
        with self._lock:
            self._runner = runner
        goal_text = ", ".join(f"{goal.predicate}({', '.join(goal.objects)})" for goal in goals)
        self._say(f"mission {name}: goals {goal_text}")
        started = time.monotonic()
        try:
            result = runner.run(Mission(tuple(goals), name))
        finally:
            with self._lock:
                self._runner = None
        steps = ", ".join(str(step) for step in result.executed) or "none"
        self._say(
            f"mission {name} {result.status.value} in {time.monotonic() - started:.1f} s "
            f"({len(result.plans)} plan(s), {result.replans} replan(s)): {result.reason}; steps run: {steps}"
        )
        return result

    def cancel(self) -> None:
        self._canceled.set()
        with self._lock:
            runner = self._runner
        if runner is not None:
            runner.cancel()

    def close(self) -> None:
        """Cancel what runs and destroy the action clients: call it once the node no longer spins."""
        self.cancel()
        for client in self._clients.values():
            client.destroy()
        self._clients = {}
        self._behaviours = {}


#: The dispatcher's plan and step lines are logged under this package logger.
PLANNING_LOGGER = "merlin2_sailor_behaviors.planning"


class ForwardToRosLogger(logging.Handler):
    """Python logging (the dispatcher's plan and step lines) into a ROS node's logger, or into
    ``say`` when given (a running account that also keeps the lines).

    One rclpy call site per severity: rclpy refuses a call site whose severity changes.
    """

    def __init__(self, node: Node, say: Say | None = None) -> None:
        super().__init__(level=logging.INFO)
        self._logger = node.get_logger()
        self._say = say

    def attach(self) -> None:
        """Start forwarding the planning lines (INFO and up)."""
        logger = logging.getLogger(PLANNING_LOGGER)
        logger.addHandler(self)
        logger.setLevel(logging.INFO)

    def detach(self) -> None:
        logging.getLogger(PLANNING_LOGGER).removeHandler(self)

    def emit(self, record: logging.LogRecord) -> None:
        message = self.format(record)
        if self._say is not None:
            self._say(message)
            return
        if record.levelno >= logging.ERROR:
            self._logger.error(message)
        elif record.levelno >= logging.WARNING:
            self._logger.warning(message)
        else:
            self._logger.info(message)
