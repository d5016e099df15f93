"""The dispatcher's side of RunPddlAction: plan steps run on the ``behaviors`` node's servers.

A :class:`PddlActionBehaviour` is a :data:`~merlin2_sailor_behaviors.planning.Behaviour`: called
with the dispatcher's blackboard, it sends the step in ``blackboard[PLAN_STEP_KEY]`` (the objects
in parameter order) to ``<prefix>/<action>`` and waits for the outcome; ``cancel_state()``
cancels the goal. An outcome other than succeeded leaves the server's reason on the blackboard
(``REASON_KEY``). Every wait is bounded: a step that runs past :func:`step_deadline` is
cancelled and aborts (the dispatcher replans), and a result lost on the way is asked for again
(:func:`~merlin2_sailor_behaviors.ros.waiting.wait_for_goal_result`). The node it is given must
be spun by another thread (an executor or a
:class:`~merlin2_sailor.ros.background_spinner.BackgroundSpinner`); :class:`RemoteBehaviours`
brings its own.

A mission runtime builds its behaviours map with :func:`behaviours_for_store` (every action the
knowledge base holds that has a server) and hands it to the Dispatcher::

    with RemoteBehaviours(store) as remote:
        dispatcher = Dispatcher(store, Planner(), remote.behaviours)
        MissionRunner(store, dispatcher).run(mission)
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable, Mapping
from types import TracebackType
from typing import Any

import rclpy
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node

from merlin2_sailor.knowledge import KnowledgeBase
from merlin2_sailor.ros.action_client import RaceFreeActionClient
from merlin2_sailor.ros.background_spinner import BackgroundSpinner
from merlin2_sailor_behaviors.actions.keys import PLAN_STEP_KEY, REASON_KEY
from merlin2_sailor_behaviors.planning.plan import PlanStep
from merlin2_sailor_behaviors.ros.waiting import WaitEnd, wait_for, wait_for_future, wait_for_goal_result
from merlin2_sailor_behaviors.state_machines import ABORT, BASIC_OUTCOMES, CANCEL, Blackboard
from merlin2_sailor_interfaces.action import RunPddlAction

DEFAULT_PREFIX = "/behaviors"
"""Where the ``behaviors`` node serves its actions under its default name."""

SERVER_GONE_SECONDS = 3.0
"""How long a running step's server may be missing from the graph before the step aborts."""

STEP_DEADLINE_FACTOR = 10.0
"""A step may run this many times its PDDL duration (MERLIN2's planner plans with durations that
are estimates, KANT's default 10 s for most actions) ..."""

STEP_DEADLINE_MARGIN = 60.0
"""... plus this many seconds, before it is cancelled and counts as failed, so that a behaviour
that never ends (or a result that never comes) makes the dispatcher replan instead of waiting
forever. An instantaneous action gets the margin alone."""


def step_deadline(step: PlanStep, factor: float = STEP_DEADLINE_FACTOR, margin: float = STEP_DEADLINE_MARGIN) -> float:
    """Seconds ``step`` may run before it is cancelled (see STEP_DEADLINE_FACTOR)."""
    return margin + factor * (step.duration or 0.0)


def describe_deadline(
    step: PlanStep, factor: float = STEP_DEADLINE_FACTOR, margin: float = STEP_DEADLINE_MARGIN
) -> str:
    """How :func:`step_deadline` came to its figure, in words."""
    if step.duration:
        return f"{factor:g} x its PDDL duration of {step.duration:g} s + {margin:g} s"
    return f"{margin:g} s for an instantaneous action"


class PddlActionBehaviour:
    """Runs plan steps of one action on its RunPddlAction server."""

    def __init__(
        self,
        node: Node,
        action_name: str,
        server_name: str | None = None,
        server_timeout: float = 5.0,
        cancel_timeout: float = 10.0,
        deadline_factor: float = STEP_DEADLINE_FACTOR,
        deadline_margin: float = STEP_DEADLINE_MARGIN,
    ) -> None:
        self.action_name = action_name
        self.server_name = server_name or f"{DEFAULT_PREFIX}/{action_name}"
        self._server_timeout = server_timeout
        self._cancel_timeout = cancel_timeout
        self._deadline = (deadline_factor, deadline_margin)
        self._client = RaceFreeActionClient(node, RunPddlAction, self.server_name,
                                            callback_group=ReentrantCallbackGroup())
        self._logger = node.get_logger()
        self._canceled = threading.Event()
        self._never = threading.Event()
        self.last_state = ""
        """The state the server's machine last entered (feedback)."""

    def server_is_ready(self) -> bool:
        return self._client.server_is_ready()

    def cancel_state(self) -> None:
        """Cancel the step being run (from any thread)."""
        self._canceled.set()

    def __call__(self, blackboard: Blackboard) -> str:
        self._canceled.clear()
        self.last_state = ""
        step: PlanStep = blackboard[PLAN_STEP_KEY]
        if step.action != self.action_name:
            return _abort(blackboard, f"{self.server_name} runs {self.action_name!r}, not {step.action!r}")
        end = wait_for(self._client.server_is_ready, self._server_timeout, self._never, self._canceled.is_set)
        if end is WaitEnd.CANCELED:
            return CANCEL
        if end is not WaitEnd.DONE:
            return _abort(blackboard, f"no {self.action_name} server at {self.server_name} after "
                                      f"{self._server_timeout:g} s; is the behaviors node running?")
        goal = RunPddlAction.Goal(action_name=step.action, objects=list(step.objects))
        sent = self._client.send_goal_async(goal, feedback_callback=self._on_feedback)
        if wait_for_future(sent, self._server_timeout, self._never) is not WaitEnd.DONE or sent.result() is None:
            return _abort(blackboard, f"{self.server_name} did not answer the goal {step}")
        handle = sent.result()
        if not handle.accepted:
            return _abort(blackboard, f"{self.server_name} rejected the goal {step}")
        server_gone = self._vanishing_server()
        deadline = step_deadline(step, *self._deadline)
        waited = wait_for_goal_result(handle, deadline, self._never,
                                      lambda: self._canceled.is_set() or server_gone())
        self._report_requeries(step, waited.requeries)
        if waited.end is WaitEnd.CANCELED and not self._canceled.is_set():
            return _abort(blackboard, f"{self.server_name} went away while running {step}")
        if waited.end is not WaitEnd.DONE:  # cancelled by the dispatcher, or past the step's deadline
            if waited.end is WaitEnd.TIMEOUT:
                self._logger.warning(f"{step} passed its deadline of {deadline:g} s; cancelling it")
            handle.cancel_goal_async()
            stopped = wait_for_goal_result(handle, self._cancel_timeout, self._never)
            self._report_requeries(step, stopped.requeries)
            if waited.end is WaitEnd.TIMEOUT:
                return _abort(blackboard, f"{step} did not end within its deadline of {deadline:g} s "
                                          f"({describe_deadline(step, *self._deadline)}); it was cancelled")
            if stopped.end is not WaitEnd.DONE:
                return _abort(blackboard, f"{step} did not stop within {self._cancel_timeout:g} s of its cancel")
            waited = stopped
        response = waited.response.result
        outcome = response.outcome if response.outcome in BASIC_OUTCOMES else ABORT
        if outcome != BASIC_OUTCOMES[0]:
            blackboard[REASON_KEY] = response.message or f"{step} ended {response.outcome!r}"
        return outcome

    def _report_requeries(self, step: PlanStep, requeries: int) -> None:
        if requeries:
            self._logger.warning(f"the result of {step} was lost on the way; asked for it again "
                                 f"({requeries} time(s))")

    def _vanishing_server(self) -> Callable[[], bool]:
        """A check that turns true once the server has been gone for SERVER_GONE_SECONDS."""
        missing_since: list[float] = []

        def gone() -> bool:
            if self._client.server_is_ready():
                missing_since.clear()
                return False
            if not missing_since:
                missing_since.append(time.monotonic())
            return time.monotonic() - missing_since[0] > SERVER_GONE_SECONDS

        return gone

    def _on_feedback(self, message: Any) -> None:
        self.last_state = message.feedback.state

    def destroy(self) -> None:
        self._client.destroy()


def _abort(blackboard: Blackboard, reason: str) -> str:
    blackboard[REASON_KEY] = reason
    return ABORT


def behaviours_for_store(
    store: KnowledgeBase,
    node: Node,
    prefix: str = DEFAULT_PREFIX,
    discovery_timeout: float = 5.0,
    **options: float,
) -> dict[str, PddlActionBehaviour]:
    """A behaviour for every action the knowledge base holds whose server appears within
    ``discovery_timeout`` seconds (all of them waited for together); ``options`` go to each
    :class:`PddlActionBehaviour`."""
    candidates = {
        action.name: PddlActionBehaviour(node, action.name, f"{prefix.rstrip('/')}/{action.name}", **options)
        for action in store.actions.get_all()
    }
    deadline = time.monotonic() + discovery_timeout
    while time.monotonic() < deadline and not all(b.server_is_ready() for b in candidates.values()):
        time.sleep(0.05)
    behaviours = {}
    for name, behaviour in candidates.items():
        if behaviour.server_is_ready():
            behaviours[name] = behaviour
        else:
            behaviour.destroy()
    return behaviours


class RemoteBehaviours:
    """The behaviours map over a node of its own, spun on a private thread; close it when done."""

    def __init__(
        self,
        store: KnowledgeBase,
        prefix: str = DEFAULT_PREFIX,
        discovery_timeout: float = 5.0,
        **options: float,
    ) -> None:
        self._spinner = BackgroundSpinner("remote-behaviours")
        node = rclpy.create_node(f"mission_behaviours_{os.getpid()}_{id(self):x}", context=self._spinner.context)
        self.node = self._spinner.add_node(node)
        self.behaviours: Mapping[str, PddlActionBehaviour] = behaviours_for_store(
            store, self.node, prefix, discovery_timeout, **options)

    def close(self) -> None:
        for behaviour in self.behaviours.values():
            behaviour.cancel_state()
        self._spinner.close()

    def __enter__(self) -> RemoteBehaviours:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, traceback: TracebackType | None
    ) -> None:
        self.close()
