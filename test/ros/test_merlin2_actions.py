"""SAILOR's behaviours as actions of the real MERLIN2 (8d1eb02), registered in the real KANT.

``python -m merlin2_sailor_behaviors.merlin2.run`` builds each action on MERLIN2's own
Merlin2FsmAction, which registers it in KANT's knowledge base under /merlin2 (MERLIN2's fixed
namespace). Skips, saying why, without SAILOR_UPSTREAM.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import threading

import pytest

from merlin2_sailor.knowledge.kant_projection import kant_duration
from merlin2_sailor.ros.stores import open_store
from merlin2_sailor_behaviors.catalogue import SAILOR_ACTIONS

pytestmark = pytest.mark.ros

ACTIONS = tuple(SAILOR_ACTIONS)
START_SECONDS = 60.0


class ReadProcess:
    """A process whose merged output is read line by line as it comes, so a test can wait for a
    line (a process's own word that it is ready) with a deadline."""

    def __init__(self, *arguments: str) -> None:
        self.process = subprocess.Popen([sys.executable, "-m", *arguments], stdout=subprocess.PIPE,
                                        stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, text=True)
        self.lines: list[str] = []
        self._reader = threading.Thread(
            target=lambda: self.lines.extend(iter(self.process.stdout.readline, "")), daemon=True)
        self._reader.start()

    @property
    def output(self) -> str:
        return "".join(self.lines)

    def said(self, prefix: str) -> bool:
        return any(line.startswith(prefix) for line in list(self.lines))

    def interrupt(self, timeout: float = 30.0) -> int:
        """Ctrl-C, then its exit status; killed (-9) if it outlives ``timeout``."""
        self.process.send_signal(signal.SIGINT)
        try:
            self.process.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        self._reader.join(timeout=5)
        return self.process.returncode


RUNNING = "running "
"""How merlin2.run says that its actions run (before it, a Ctrl-C is an interrupted start, exit 130)."""


def registered_actions(location: str) -> dict[str, float]:
    with open_store(location) as kant:
        return {action.name: action.duration for action in kant.actions.get_all()}


def test_ctrl_c_withdraws_every_action_once_and_exits_0(start_kant_node, ros_probe) -> None:
    kant = start_kant_node("/merlin2")
    actions = ReadProcess("merlin2_sailor_behaviors.merlin2.run")  # every action
    try:
        assert ros_probe.wait_for(lambda: set(registered_actions(kant.location)) == set(ACTIONS),
                                  timeout=START_SECONDS), f"the actions never appeared in KANT:\n{actions.output}"
        # Each with its own duration, in KANT's whole seconds.
        assert registered_actions(kant.location) == {
            name: float(kant_duration(SAILOR_ACTIONS[name].pddl.duration)) for name in ACTIONS}
        assert ros_probe.wait_for(lambda: actions.said(RUNNING), timeout=START_SECONDS), actions.output
    finally:
        code = actions.interrupt()
    output = actions.output
    assert code == 0, output
    assert "Traceback" not in output and "Exception in thread" not in output, output
    assert "context is invalid" not in output, output
    assert registered_actions(kant.location) == {}, output
    assert kant.process.poll() is None


def registered_action(location: str, name: str):  # noqa: ANN201 - a PddlAction or None
    with open_store(location) as kant:
        return kant.actions.get(name)


def navigation_registered_by(module: str, location: str, ros_probe, ready: str = "") -> tuple[object, int, str]:  # noqa: ANN001
    """Start ``module`` until KANT holds its ``navigation`` action (and, if given, it said a line
    starting with ``ready``); that action, then its exit status and output once stopped with Ctrl-C.

    MERLIN2's own action node sometimes outlives SIGINT (seen once in a loaded CI run, 5 December
    2026): killed, it says so by its status (-9), which only SAILOR's is held to."""
    process = ReadProcess(module, "navigation")
    try:
        assert ros_probe.wait_for(lambda: registered_action(location, "navigation") is not None,
                                  timeout=START_SECONDS), f"{module}'s navigation never appeared in KANT"
        action = registered_action(location, "navigation")
        if ready:
            assert ros_probe.wait_for(lambda: process.said(ready), timeout=START_SECONDS), process.output
    finally:
        code = process.interrupt()
    return action, code, process.output


def test_sailors_navigation_is_merlin2s_navigation_as_kant_holds_it(start_kant_node, ros_probe) -> None:
    """SAILOR's navigation can stand in for merlin2_basic_actions': the same PDDL action in KANT."""
    kant = start_kant_node("/merlin2")
    merlin2_navigation, _, _ = navigation_registered_by(
        "merlin2_basic_actions.merlin2_navigation_fsm_action", kant.location, ros_probe)
    with open_store(kant.location) as store:  # MERLIN2's action may outlive its process
        store.actions.delete("navigation")
    sailor_navigation, code, output = navigation_registered_by(
        "merlin2_sailor_behaviors.merlin2.run", kant.location, ros_probe, ready=RUNNING)
    assert code == 0, output
    # The same action: effects compared as a set (MERLIN2 lists the at-end effect first).
    def signature(action):  # noqa: ANN001, ANN202
        return (action.name, action.parameters, set(action.conditions), set(action.effects), action.durative,
                action.duration)

    assert signature(sailor_navigation) == signature(merlin2_navigation)
    assert [(p.name, p.type) for p in sailor_navigation.parameters] == [("o", "wp"), ("d", "wp")]


@pytest.mark.parametrize(("module", "upstream_module", "arguments"), [
    ("merlin2_sailor_behaviors.merlin2.mission", "merlin2_mission", ["explored(kitchen)"]),
    ("merlin2_sailor_behaviors.merlin2.run", "merlin2_fsm_action", ["explore"]),
], ids=["mission", "actions"])
def test_without_kant_it_is_one_line_and_status_2_not_a_hang(upstream_stack, module, upstream_module, arguments):
    """KANT's DAOs wait for its node forever (MERLIN2 registers actions and reads goals through
    them); the mission and the actions give up after --wait, saying why."""
    upstream_stack(upstream_module)
    process = subprocess.run([sys.executable, "-m", module, *arguments, "--wait", "2"],
                             capture_output=True, text=True, timeout=60, stdin=subprocess.DEVNULL)
    assert process.returncode == 2, process.stdout + process.stderr
    assert "cannot start: KANT's knowledge base is not reachable" in process.stderr
    assert "Traceback" not in process.stdout + process.stderr
