"""A scenario run has a deadline: a launch still running then is stopped and reported as hung."""

from __future__ import annotations

import io
import time

from merlin2_sailor.launcher.spec import LaunchSpec, NodeSpec
from merlin2_sailor_demos.scenario_runner import launch


def _spec(seconds: str) -> LaunchSpec:
    return LaunchSpec(nodes=(NodeSpec(executable="sleep", arguments=(seconds,)),))


def test_a_launch_past_its_deadline_is_stopped_and_said_to_have_hung() -> None:
    started = time.monotonic()
    result, hung = launch(_spec("60"), io.StringIO(), grace_period=2.0, deadline=0.5)
    assert hung and time.monotonic() - started < 15.0
    assert "deadline of 0.5 s" in result.stop_reason


def test_a_launch_that_ends_in_time_has_not_hung() -> None:
    result, hung = launch(_spec("0.1"), io.StringIO(), grace_period=2.0, deadline=30.0)
    assert not hung and result.succeeded and result.stop_reason == "sleep finished"
