"""Results of action goals are never lost, and no step waits past its deadline.

The lost result of the demo's hang (rclpy's ActionClient records a request's future only after
sending it, so an executor thread can take the response first and ignore it) is made certain
here by holding the client in that window for a moment after it sends a result request, the way
a busy machine does by chance. The server answers at once: its goals end before the client asks.
"""

from __future__ import annotations

import threading
import time
import uuid
from collections.abc import Iterator
from typing import Any

import pytest

pytestmark = pytest.mark.ros

WINDOW_SECONDS = 0.3
"""How long the client is held between sending a result request and recording its future."""


class SlowSender:
    """An rcl action client handle that pauses after sending the first ``pauses`` result requests."""

    def __init__(self, handle: Any, pauses: int) -> None:
        self._handle = handle
        self.pauses = pauses

    def send_result_request(self, request: Any) -> int:
        sequence_number = self._handle.send_result_request(request)
        if self.pauses > 0:
            self.pauses -= 1
            time.sleep(WINDOW_SECONDS)
        return sequence_number

    def __getattr__(self, name: str) -> Any:
        return getattr(self._handle, name)


class PddlActionServer:
    """RunPddlAction on ``name``, spun by its own thread: goals succeed at once, or, with
    ``block``, run until cancelled."""

    def __init__(self, name: str, block: bool = False) -> None:
        import rclpy
        from rclpy.action import ActionServer, CancelResponse
        from rclpy.callback_groups import ReentrantCallbackGroup
        from rclpy.executors import MultiThreadedExecutor

        from merlin2_sailor_interfaces.action import RunPddlAction

        self.cancelled = threading.Event()
        self._block = block
        self._type = RunPddlAction
        self._context = rclpy.Context()
        rclpy.init(context=self._context)
        self.node = rclpy.create_node(f"pddl_server_{uuid.uuid4().hex[:6]}", context=self._context)
        # Several threads: a goal that runs until cancelled must not keep its cancel from being heard.
        self._executor = MultiThreadedExecutor(num_threads=3, context=self._context)
        self._executor.add_node(self.node)
        self._thread = threading.Thread(target=self._spin, daemon=True)
        self._thread.start()
        self._server = ActionServer(self.node, RunPddlAction, name, self._execute,
                                    cancel_callback=lambda goal: CancelResponse.ACCEPT,
                                    callback_group=ReentrantCallbackGroup())

    def _execute(self, goal: Any) -> Any:
        while self._block and not goal.is_cancel_requested:
            time.sleep(0.02)
        if goal.is_cancel_requested:
            self.cancelled.set()
            goal.canceled()
            return self._type.Result(outcome="canceled", message="cancelled as asked")
        goal.succeed()
        return self._type.Result(outcome="succeeded", message="")

    def _spin(self) -> None:
        from rclpy.executors import ExternalShutdownException

        try:
            self._executor.spin()
        except ExternalShutdownException:
            pass

    def close(self) -> None:
        import rclpy

        self._block = False
        rclpy.try_shutdown(context=self._context)
        self._thread.join(timeout=5.0)


@pytest.fixture
def action_name() -> Iterator[str]:
    yield f"/test_results_{uuid.uuid4().hex[:8]}/explore"


@pytest.fixture
def start_server(action_name: str) -> Iterator[Any]:
    servers: list[PddlActionServer] = []

    def start(block: bool = False) -> PddlActionServer:
        servers.append(PddlActionServer(action_name, block))
        return servers[-1]

    yield start
    for server in servers:
        server.close()


def _send(client: Any, probe: Any) -> Any:
    from merlin2_sailor_interfaces.action import RunPddlAction

    assert probe.wait_for(client.server_is_ready), "the RunPddlAction server never appeared"
    sent = client.send_goal_async(RunPddlAction.Goal(action_name="explore", objects=["kitchen"]))
    assert probe.wait_for(sent.done), "the goal was never answered"
    handle = sent.result()
    assert handle.accepted
    return handle


def test_rclpy_action_client_loses_a_result_that_comes_back_at_once(ros_probe, action_name: str,
                                                                    start_server) -> None:
    """The upstream race itself: without the guard, the result response is ignored for good."""
    from action_msgs.msg import GoalStatus
    from rclpy.action import ActionClient

    from merlin2_sailor_interfaces.action import RunPddlAction

    start_server()
    client = ActionClient(ros_probe.node, RunPddlAction, action_name)
    handle = _send(client, ros_probe)
    assert ros_probe.wait_for(lambda: handle.status == GoalStatus.STATUS_SUCCEEDED), "the goal never ended"
    client._client_handle = SlowSender(client._client_handle, pauses=1)
    result = handle.get_result_async()
    assert not ros_probe.wait_for(result.done, timeout=3.0), "rclpy no longer loses this result: drop the guard"


def test_race_free_client_gets_every_result(ros_probe, action_name: str, start_server) -> None:
    from merlin2_sailor.ros.action_client import RaceFreeActionClient
    from merlin2_sailor_interfaces.action import RunPddlAction

    start_server()
    client = RaceFreeActionClient(ros_probe.node, RunPddlAction, action_name)
    client._client_handle = SlowSender(client._client_handle, pauses=5)
    for _ in range(5):
        result = _send(client, ros_probe).get_result_async()
        assert ros_probe.wait_for(result.done, timeout=5.0), "a result was lost"
        assert result.result().result.outcome == "succeeded"


def test_a_lost_result_is_asked_for_again(ros_probe, action_name: str, start_server) -> None:
    """Whatever loses a result (here the same race, on a plain client), the waiter recovers it
    from the goal's status."""
    from rclpy.action import ActionClient

    from merlin2_sailor_behaviors.ros.waiting import WaitEnd, wait_for_goal_result
    from merlin2_sailor_interfaces.action import RunPddlAction

    start_server()
    client = ActionClient(ros_probe.node, RunPddlAction, action_name)
    handle = _send(client, ros_probe)
    client._client_handle = SlowSender(client._client_handle, pauses=1)
    waited = wait_for_goal_result(handle, 10.0, threading.Event())
    assert waited.end is WaitEnd.DONE
    assert waited.requeries >= 1
    assert waited.response.result.outcome == "succeeded"


def test_a_step_past_its_deadline_is_cancelled_and_aborts(ros_probe, action_name: str, start_server) -> None:
    from merlin2_sailor_behaviors.actions.keys import PLAN_STEP_KEY, REASON_KEY
    from merlin2_sailor_behaviors.planning.plan import PlanStep
    from merlin2_sailor_behaviors.ros.pddl_action_client import PddlActionBehaviour
    from merlin2_sailor_behaviors.state_machines import ABORT, Blackboard

    server = start_server(block=True)
    behaviour = PddlActionBehaviour(ros_probe.node, "explore", action_name, deadline_factor=0.5, deadline_margin=1.0)
    blackboard = Blackboard()
    blackboard[PLAN_STEP_KEY] = PlanStep("explore", ("kitchen",), duration=2.0)
    started = time.monotonic()
    outcome = behaviour(blackboard)
    assert outcome == ABORT
    assert server.cancelled.is_set(), "the step ran on after its deadline"
    assert "did not end within its deadline of 2 s" in blackboard[REASON_KEY]
    assert time.monotonic() - started < 15.0
