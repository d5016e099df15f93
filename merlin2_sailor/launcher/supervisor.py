"""Run the processes of a launch, prefix their output, and stop them all together.

Each node runs in its own process session, so a Ctrl-C in the terminal reaches only the
supervisor, which then stops the nodes: SIGINT (rclpy's clean shutdown), last-started first,
then SIGTERM after a grace period, then SIGKILL. The launch ends when the user interrupts it, when
a node whose exit policy is ``shutdown`` ends, or when an optional duration has passed; the result
records how each process ended so the summary can say exactly what went wrong.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from enum import Enum
from pathlib import Path
from typing import IO

from merlin2_sailor.launcher.command import build_command
from merlin2_sailor.launcher.spec import ExitPolicy, LaunchSpec, NodeSpec

_POLL_SECONDS = 0.05
_STOP_STEP_SECONDS = 3.0  # how long one node may take to leave before the next is asked
_COLOURS = ("\033[36m", "\033[32m", "\033[33m", "\033[35m", "\033[34m", "\033[91m")
_RESET = "\033[0m"


class Ending(Enum):
    """How one process ended."""

    FINISHED = "finished"  # exited with code 0 on its own
    CRASHED = "crashed"  # exited with a non-zero code, or died of a signal, on its own
    STOPPED = "stopped"  # exited cleanly after the supervisor's SIGINT
    TERMINATED = "terminated"  # ignored SIGINT for the grace period, ended by SIGTERM
    KILLED = "killed"  # ignored SIGTERM too, ended by SIGKILL


@dataclass(frozen=True)
class ProcessOutcome:
    label: str
    pid: int
    return_code: int
    ending: Ending

    @property
    def clean(self) -> bool:
        return self.ending in (Ending.FINISHED, Ending.STOPPED)


@dataclass(frozen=True)
class LaunchResult:
    outcomes: tuple[ProcessOutcome, ...]
    stop_reason: str

    @property
    def succeeded(self) -> bool:
        return all(outcome.clean for outcome in self.outcomes)

    def summary(self) -> str:
        width = max([len(outcome.label) for outcome in self.outcomes] + [4])
        lines = [f"launch ended: {self.stop_reason}", f"  {'node':<{width}}  {'pid':>7}  exit  ending"]
        for outcome in self.outcomes:
            lines.append(
                f"  {outcome.label:<{width}}  {outcome.pid:>7}  {outcome.return_code:>4}  "
                f"{outcome.ending.value}"
            )
        lines.append("all nodes ended cleanly" if self.succeeded else "some nodes did NOT end cleanly")
        return "\n".join(lines)


@dataclass
class _Running:
    node: NodeSpec
    process: subprocess.Popen[bytes]
    reader: threading.Thread
    signal_sent: int = 0  # the strongest signal the supervisor sent, 0 for none


class Supervisor:
    """Start the nodes of a LaunchSpec and supervise them until the launch must end."""

    def __init__(
        self,
        spec: LaunchSpec,
        output: IO[str] | None = None,
        grace_period: float = 10.0,
        colour: bool | None = None,
    ) -> None:
        self._spec = spec
        self._output = output if output is not None else sys.stdout
        self._grace_period = grace_period
        self._colour = colour if colour is not None else self._output.isatty()
        self._output_lock = threading.Lock()
        self._stop_requested = threading.Event()
        self._stop_reason = ""
        self._running: list[_Running] = []

    def request_stop(self, reason: str = "interrupted by the user") -> None:
        """Ask the launch to end; safe to call from a signal handler or another thread."""
        if not self._stop_requested.is_set():
            self._stop_reason = reason
            self._stop_requested.set()

    def run(self, duration: float | None = None) -> LaunchResult:
        """Start every node, wait until the launch must end, stop the rest, and report."""
        with tempfile.TemporaryDirectory(prefix="sailor-launch-") as scratch:
            try:
                for index, node in enumerate(self._spec.nodes):
                    self._start(node, Path(scratch), index)
                self._wait(duration)
            finally:
                self._stop_all()
        return LaunchResult(tuple(self._outcome(entry) for entry in self._running), self._stop_reason)

    def _start(self, node: NodeSpec, scratch: Path, index: int) -> None:
        command = build_command(node, scratch)
        environment = {**os.environ, **self._spec.environment, "PYTHONUNBUFFERED": "1"}
        process = subprocess.Popen(
            command,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
            env=environment,
            start_new_session=True,
        )
        prefix = f"[{node.label}] "
        if self._colour:
            prefix = f"{_COLOURS[index % len(_COLOURS)]}{prefix}{_RESET}"
        reader = threading.Thread(
            target=self._relay_output, args=(process, prefix), name=f"relay-{node.label}", daemon=True
        )
        reader.start()
        self._running.append(_Running(node, process, reader))
        self._say(f"started {node.label} (pid {process.pid}): {' '.join(command)}")

    def _wait(self, duration: float | None) -> None:
        deadline = None if duration is None else time.monotonic() + duration
        while not self._stop_requested.wait(_POLL_SECONDS):
            for entry in self._running:
                return_code = entry.process.poll()
                if return_code is not None and entry.node.on_exit is ExitPolicy.SHUTDOWN:
                    verb = "finished" if return_code == 0 else f"exited with code {return_code}"
                    self.request_stop(f"{entry.node.label} {verb}")
                    break
            if deadline is not None and time.monotonic() >= deadline:
                self.request_stop(f"the launch's duration of {duration:g} s elapsed")

    def _stop_all(self) -> None:
        if not self._stop_reason:
            self._stop_reason = "the launch failed to start"
        self._interrupt_in_reverse_order()
        for signal_number, patience in (
            (signal.SIGTERM, 3.0),
            (signal.SIGKILL, 3.0),
        ):
            alive = [entry for entry in self._running if entry.process.poll() is None]
            if not alive:
                break
            for entry in alive:
                self._signal(entry, signal_number)
            deadline = time.monotonic() + patience
            while time.monotonic() < deadline and any(e.process.poll() is None for e in alive):
                time.sleep(_POLL_SECONDS)
        for entry in self._running:
            entry.process.wait()
            entry.reader.join(timeout=2.0)

    def _interrupt_in_reverse_order(self) -> None:
        """SIGINT the nodes last-started first, each given a moment to leave before the next.

        A launch file lists what others need first (the knowledge base before the nodes that
        write to it), so stopping in reverse lets each node's shutdown (a last sync, withdrawing
        its actions) still reach what it depends on. A node that does not leave within
        ``_STOP_STEP_SECONDS`` does not hold up the rest; the grace period runs from the last SIGINT.
        """
        for entry in reversed(self._running):
            if entry.process.poll() is not None:
                continue
            self._signal(entry, signal.SIGINT)
            step_end = time.monotonic() + min(_STOP_STEP_SECONDS, self._grace_period)
            while time.monotonic() < step_end and entry.process.poll() is None:
                time.sleep(_POLL_SECONDS)
        deadline = time.monotonic() + self._grace_period
        while time.monotonic() < deadline and any(entry.process.poll() is None for entry in self._running):
            time.sleep(_POLL_SECONDS)

    @staticmethod
    def _signal(entry: _Running, signal_number: int) -> None:
        entry.signal_sent = signal_number
        try:
            os.killpg(entry.process.pid, signal_number)
        except ProcessLookupError:
            pass

    def _outcome(self, entry: _Running) -> ProcessOutcome:
        return_code = entry.process.returncode
        if entry.signal_sent == signal.SIGKILL:
            ending = Ending.KILLED
        elif entry.signal_sent == signal.SIGTERM:
            ending = Ending.TERMINATED
        elif entry.signal_sent == signal.SIGINT:
            stopped_cleanly = return_code in (0, -signal.SIGINT, 128 + signal.SIGINT)
            ending = Ending.STOPPED if stopped_cleanly else Ending.CRASHED
        else:
            ending = Ending.FINISHED if return_code == 0 else Ending.CRASHED
        return ProcessOutcome(entry.node.label, entry.process.pid, return_code, ending)

    def _relay_output(self, process: subprocess.Popen[bytes], prefix: str) -> None:
        assert process.stdout is not None
        for raw_line in iter(process.stdout.readline, b""):
            self._say(raw_line.decode(errors="replace").rstrip("\n"), prefix)
        process.stdout.close()

    def _say(self, line: str, prefix: str = "[launch] ") -> None:
        with self._output_lock:
            self._output.write(f"{prefix}{line}\n")
            self._output.flush()
