"""One SAILOR action served as a RunPddlAction action server.

A goal names the action and its objects in parameter order. The server builds a fresh state
machine for it and runs it on a worker thread with the objects on the blackboard (as the
dispatcher would); the node's executor is never blocked by a running behaviour. Only when the
machine has ended is the goal handed to rclpy's execute step, which just reports the outcome and
the reason. Meanwhile :meth:`PddlActionServer.publish_progress` (called by the node's timer)
publishes each state the machine enters as feedback, and a cancel request is accepted and
reaches the running state through ``cancel_state()``.

The robot has one body: a :class:`Body` shared by the node's servers lets one behaviour run at a
time, and a goal that arrives while another runs is aborted at once, saying which one runs. Bad
goals (a wrong action name, the wrong number of objects) and failing behaviours end ``aborted``
with a message; nothing a goal carries can stop the node.
"""

from __future__ import annotations

import threading
import traceback
from dataclasses import dataclass, field

from rclpy.action import ActionServer, CancelResponse
from rclpy.action.server import ServerGoalHandle
from rclpy.callback_groups import CallbackGroup
from rclpy.node import Node

from merlin2_sailor.errors import KnowledgeError
from merlin2_sailor_behaviors.actions.context import BehaviorContext, Log
from merlin2_sailor_behaviors.actions.keys import REASON_KEY, WARNINGS_KEY
from merlin2_sailor_behaviors.actions.progress import active_state_path
from merlin2_sailor_behaviors.actions.sailor_action import SailorAction
from merlin2_sailor_behaviors.state_machines import ABORT, CANCEL, SUCCEED, Blackboard, State
from merlin2_sailor_interfaces.action import RunPddlAction


class Body:
    """Which behaviour holds the robot now; one at a time."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._holder: str | None = None

    def acquire(self, name: str) -> str | None:
        """Take the body for ``name``; None when taken, else the name of who holds it."""
        with self._lock:
            if self._holder is not None:
                return self._holder
            self._holder = name
            return None

    def release(self) -> None:
        with self._lock:
            self._holder = None


@dataclass
class _Run:
    """One goal: its handle, its machine while it runs, its result once it ended."""

    goal_handle: ServerGoalHandle
    machine: State | None = None
    last_state: str = ""
    result: RunPddlAction.Result | None = None
    cancel: threading.Event = field(default_factory=threading.Event)


class PddlActionServer:
    """Serves ``action`` at ``server_name``; its machines are built from ``context``."""

    def __init__(
        self,
        node: Node,
        action: SailorAction,
        context: BehaviorContext,
        server_name: str,
        body: Body,
        stopping: threading.Event,
        log: Log,
        callback_group: CallbackGroup | None = None,
    ) -> None:
        self.action = action
        self._context = context
        self._body = body
        self._stopping = stopping
        self._log = log
        self._lock = threading.Lock()
        self._runs: dict[bytes, _Run] = {}
        self._idle = threading.Event()
        self._idle.set()
        self._server = ActionServer(
            node,
            RunPddlAction,
            server_name,
            execute_callback=self._report,
            handle_accepted_callback=self._start,
            cancel_callback=self._cancel,
            callback_group=callback_group,
        )

    # Life cycle.

    def cancel_all(self) -> None:
        """Cancel every running machine (the node is stopping)."""
        with self._lock:
            runs = list(self._runs.values())
        for run in runs:
            self._cancel_run(run)

    def wait_idle(self, timeout: float) -> bool:
        """Wait until no machine of this server runs; True when none does."""
        return self._idle.wait(timeout)

    def destroy(self) -> None:
        self._server.destroy()

    def running_machines(self) -> list[State]:
        """The machines of the goals running now."""
        with self._lock:
            return [run.machine for run in self._runs.values() if run.machine is not None and run.result is None]

    def publish_progress(self) -> None:
        """Publish, as feedback, the state each running machine entered since the last call.

        Also repeats a cancellation to a machine that is running: one that arrived in the instant
        between the machine being built and starting would otherwise be forgotten by its start.
        """
        with self._lock:
            runs = [run for run in self._runs.values() if run.machine is not None and run.result is None]
        for run in runs:
            path = active_state_path(run.machine)
            if path and run.cancel.is_set():
                run.machine.cancel_state()
            if path and path != run.last_state:
                run.last_state = path
                run.goal_handle.publish_feedback(RunPddlAction.Feedback(state=path))

    # rclpy callbacks (on the executor).

    def _start(self, goal_handle: ServerGoalHandle) -> None:
        run = _Run(goal_handle)
        with self._lock:
            self._runs[_goal_id(goal_handle)] = run
            self._idle.clear()
        threading.Thread(target=self._work, args=(run,), name=f"behavior-{self.action.name}", daemon=True).start()

    def _cancel(self, goal_handle: ServerGoalHandle) -> CancelResponse:
        with self._lock:
            run = self._runs.get(_goal_id(goal_handle))
        if run is not None:
            self._cancel_run(run)
        return CancelResponse.ACCEPT

    def _report(self, goal_handle: ServerGoalHandle) -> RunPddlAction.Result:
        """rclpy's execute step, reached once the machine has ended: report how."""
        with self._lock:
            run = self._runs.pop(_goal_id(goal_handle), None)
            if not self._runs:
                self._idle.set()
        result = run.result if run is not None and run.result is not None else RunPddlAction.Result(
            outcome=ABORT, message="the goal was lost by its server")
        if result.outcome == SUCCEED:
            goal_handle.succeed()
        elif result.outcome == CANCEL and goal_handle.is_cancel_requested:
            goal_handle.canceled()
        else:
            goal_handle.abort()
        return result

    # The worker thread.

    def _cancel_run(self, run: _Run) -> None:
        with self._lock:
            run.cancel.set()
            machine = run.machine
        if machine is not None:
            machine.cancel_state()

    def _work(self, run: _Run) -> None:
        request = run.goal_handle.request
        step = f"{self.action.name}({', '.join(request.objects)})"
        try:
            outcome, message = self._run(run, request.action_name, list(request.objects))
        except Exception as error:  # a bug must not take the node down; report it instead
            self._log("error", f"{step} failed: {traceback.format_exc()}")
            outcome, message = ABORT, f"the {self.action.name} behaviour failed: {error!r}"
        run.result = RunPddlAction.Result(outcome=outcome, message=message)
        ending = f"{step} {outcome}" + (f": {message}" if message else "")
        self._log("info" if outcome == SUCCEED else "warning", ending)
        if self._stopping.is_set():
            self._forget(run)  # the executor is gone: nobody would report it; clients see the server go
            return
        try:
            run.goal_handle.execute()  # hands the goal to the executor, which calls _report
        except Exception as error:  # the node began stopping just now
            self._log("warning", f"could not report {step}: {error!r}")
            self._forget(run)

    def _forget(self, run: _Run) -> None:
        with self._lock:
            self._runs.pop(_goal_id(run.goal_handle), None)
            if not self._runs:
                self._idle.set()

    def _run(self, run: _Run, action_name: str, objects: list[str]) -> tuple[str, str]:
        if action_name and action_name != self.action.name:
            return ABORT, f"this server runs {self.action.name!r}, not {action_name!r}; send it to that action's server"
        try:
            blackboard = self.action.blackboard_for(objects)
        except KnowledgeError as error:
            return ABORT, str(error)
        holder = self._body.acquire(self.action.name)
        if holder is not None:
            return ABORT, f"the robot is busy running {holder}; one behaviour runs at a time"
        try:
            machine = self.action.make_state_machine(self._context)
            with self._lock:
                run.machine = machine
                canceled = run.cancel.is_set()
            if canceled or self._stopping.is_set():
                return CANCEL, "cancelled before it started"
            outcome = machine(blackboard)
        finally:
            self._body.release()
        return outcome, _message(outcome, blackboard)


def _goal_id(goal_handle: ServerGoalHandle) -> bytes:
    return bytes(goal_handle.goal_id.uuid)


def _message(outcome: str, blackboard: Blackboard) -> str:
    """The reason for an abort; for other outcomes, the warnings gathered on the way."""
    if outcome == ABORT and REASON_KEY in blackboard:
        return str(blackboard[REASON_KEY])
    warnings = list(blackboard[WARNINGS_KEY]) if WARNINGS_KEY in blackboard else []
    return "; ".join(str(warning) for warning in warnings)
