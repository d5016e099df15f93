"""SAILOR's behaviours as actions of the real MERLIN2 (8d1eb02), registered in the real KANT.

``python -m merlin2_sailor_behaviors.merlin2.run`` builds each action on MERLIN2's own
Merlin2FsmAction, which registers it in KANT's knowledge base under /merlin2 (MERLIN2's fixed
namespace). Skips, saying why, without SAILOR_UPSTREAM.
"""

from __future__ import annotations

import signal
import subprocess
import sys

import pytest

from merlin2_sailor.knowledge.kant_projection import kant_duration
from merlin2_sailor.ros.stores import open_store
from merlin2_sailor_behaviors.catalogue import SAILOR_ACTIONS

pytestmark = pytest.mark.ros

ACTIONS = tuple(SAILOR_ACTIONS)
START_SECONDS = 60.0


def registered_actions(location: str) -> dict[str, float]:
    with open_store(location) as kant:
        return {action.name: action.duration for action in kant.actions.get_all()}


def test_ctrl_c_withdraws_every_action_once_and_exits_0(start_kant_node, ros_probe) -> None:
    kant = start_kant_node("/merlin2")
    process = subprocess.Popen(
        [sys.executable, "-m", "merlin2_sailor_behaviors.merlin2.run"],  # every action
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, text=True,
    )
    try:
        assert ros_probe.wait_for(lambda: set(registered_actions(kant.location)) == set(ACTIONS),
                                  timeout=START_SECONDS), "the actions never appeared in KANT"
        # Each with its own duration, in KANT's whole seconds.
        assert registered_actions(kant.location) == {
            name: float(kant_duration(SAILOR_ACTIONS[name].pddl.duration)) for name in ACTIONS}
        process.send_signal(signal.SIGINT)
        output, _ = process.communicate(timeout=30)
    finally:
        if process.poll() is None:
            process.kill()
            process.communicate()
    assert process.returncode == 0, output
    assert "Traceback" not in output and "Exception in thread" not in output, output
    assert "context is invalid" not in output, output
    assert registered_actions(kant.location) == {}, output
    assert kant.process.poll() is None
