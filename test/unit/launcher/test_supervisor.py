"""The supervisor with real child processes: output relay, clean stop, crash handling."""

from __future__ import annotations

import io
import sys
import textwrap
import threading
import time
from pathlib import Path

from merlin2_sailor.launcher.spec import parse_launch_document
from merlin2_sailor.launcher.supervisor import Ending, Supervisor

# A stand-in node: prints a line, then waits; exits 0 on SIGINT like an rclpy node does.
POLITE_NODE = textwrap.dedent("""
    import signal, sys, time
    signal.signal(signal.SIGINT, lambda *_: sys.exit(0))
    print("hello from " + sys.argv[1], flush=True)
    while True:
        time.sleep(0.05)
""")
STUBBORN_NODE = textwrap.dedent("""
    import signal, time
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    print("ignoring SIGINT", flush=True)
    while True:
        time.sleep(0.05)
""")
CRASHING_NODE = "import sys, time; time.sleep(0.3); print('boom', flush=True); sys.exit(3)"


def launch(tmp_path: Path, scripts: dict[str, str], on_exit: dict[str, str] | None = None) -> Supervisor:
    nodes = []
    for name, source in scripts.items():
        script = tmp_path / f"{name}.py"
        script.write_text(source)
        nodes.append({
            "executable": sys.executable, "name": name, "arguments": [str(script), name],
            "on_exit": (on_exit or {}).get(name, "shutdown"),
        })
    spec = parse_launch_document({"nodes": nodes}, base_directory=tmp_path)
    return Supervisor(spec, output=io.StringIO(), grace_period=2.0, colour=False)


def output_of(supervisor: Supervisor) -> str:
    return supervisor._output.getvalue()  # type: ignore[attr-defined]


def test_two_nodes_run_with_prefixed_output_and_stop_cleanly_after_the_duration(tmp_path: Path) -> None:
    supervisor = launch(tmp_path, {"alpha": POLITE_NODE, "beta": POLITE_NODE})
    result = supervisor.run(duration=1.5)
    text = output_of(supervisor)
    assert "[alpha] hello from alpha" in text
    assert "[beta] hello from beta" in text
    assert [outcome.ending for outcome in result.outcomes] == [Ending.STOPPED, Ending.STOPPED]
    assert result.succeeded
    assert "duration" in result.stop_reason


def test_a_crashing_node_stops_the_others_and_fails_the_launch(tmp_path: Path) -> None:
    supervisor = launch(tmp_path, {"steady": POLITE_NODE, "fragile": CRASHING_NODE})
    started = time.monotonic()
    result = supervisor.run(duration=30.0)
    assert time.monotonic() - started < 10.0
    endings = {outcome.label: (outcome.ending, outcome.return_code) for outcome in result.outcomes}
    assert endings == {"steady": (Ending.STOPPED, 0), "fragile": (Ending.CRASHED, 3)}
    assert result.stop_reason == "fragile exited with code 3"
    assert not result.succeeded
    assert "[fragile] boom" in output_of(supervisor)
    assert "did NOT end cleanly" in result.summary()


def test_a_node_that_may_exit_is_let_go(tmp_path: Path) -> None:
    one_shot = "print('done', flush=True)"
    supervisor = launch(tmp_path, {"steady": POLITE_NODE, "tool": one_shot}, on_exit={"tool": "ignore"})
    result = supervisor.run(duration=1.5)
    endings = {outcome.label: outcome.ending for outcome in result.outcomes}
    assert endings == {"steady": Ending.STOPPED, "tool": Ending.FINISHED}
    assert result.succeeded


def test_a_node_ignoring_sigint_is_terminated_and_reported(tmp_path: Path) -> None:
    supervisor = launch(tmp_path, {"stubborn": STUBBORN_NODE})
    result = supervisor.run(duration=1.0)
    assert result.outcomes[0].ending is Ending.TERMINATED
    assert not result.succeeded


def test_request_stop_from_another_thread_ends_the_launch(tmp_path: Path) -> None:
    supervisor = launch(tmp_path, {"alpha": POLITE_NODE})
    threading.Timer(0.8, supervisor.request_stop).start()
    result = supervisor.run()
    assert result.stop_reason == "interrupted by the user"
    assert result.succeeded


# Writes the moment it got SIGINT to <name>.stopped, then lingers a little as a node's shutdown does.
RECORDING_NODE = textwrap.dedent("""
    import pathlib, signal, sys, time
    def leave(*_):
        pathlib.Path(sys.argv[0]).with_suffix(".stopped").write_text(repr(time.monotonic()))
        time.sleep(0.2)
        sys.exit(0)
    signal.signal(signal.SIGINT, leave)
    print("up", flush=True)
    while True:
        time.sleep(0.05)
""")


def test_nodes_are_interrupted_last_started_first(tmp_path: Path) -> None:
    """The knowledge base (listed first) must outlive the nodes whose shutdown still writes to it."""
    names = ["knowledge_base", "anchoring", "behaviors"]
    supervisor = launch(tmp_path, {name: RECORDING_NODE for name in names})
    result = supervisor.run(duration=1.5)
    assert result.succeeded
    stopped_at = {name: float((tmp_path / f"{name}.stopped").read_text()) for name in names}
    assert sorted(names, key=stopped_at.get) == ["behaviors", "anchoring", "knowledge_base"]
    assert stopped_at["knowledge_base"] - stopped_at["behaviors"] >= 0.3  # each had left before the next


def test_a_node_ignoring_sigint_does_not_keep_the_others_from_their_sigint(tmp_path: Path) -> None:
    supervisor = launch(tmp_path, {"first": RECORDING_NODE, "stubborn": STUBBORN_NODE})
    result = supervisor.run(duration=1.0)
    endings = {outcome.label: outcome.ending for outcome in result.outcomes}
    assert endings == {"first": Ending.STOPPED, "stubborn": Ending.TERMINATED}
    assert (tmp_path / "first.stopped").exists()
