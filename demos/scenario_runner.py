"""Run the mission demo of one scenario as a launch: its own data folder, DDS domain and deadline.

``launch/demo.yaml`` is loaded with ``SAILOR_DATA`` pointing at the run's folder, and the
scenario's world file, the seed and the matcher are appended to the nodes' parameters (the
last value wins, as with ``--params-file``), so the launch file stays the one source of
everything else. A run that has not ended by itself at its deadline is stopped and counted as a
hang; its verdict comes from the scorecard.json the mission demo wrote (none: a crash).
"""

from __future__ import annotations

import dataclasses
import json
import os
import signal
import threading
import time
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from types import FrameType
from typing import IO, Any

import yaml

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.launcher import Supervisor, load_launch_file
from merlin2_sailor.launcher.spec import LaunchSpec
from merlin2_sailor.launcher.supervisor import LaunchResult
from merlin2_sailor.resources import config_file, find_launch_file
from merlin2_sailor_demos.report.scenario_table import CRASH, HANG, ScenarioRun
from merlin2_sailor_demos.report.verdict import judge
from merlin2_sailor_demos.scenarios import ScenarioEntry

DEMO_LAUNCH = "demo"
DATA_VARIABLE = "SAILOR_DATA"  # what launch/demo.yaml reads its folders from
FAST_DDS_PROFILE_VARIABLE = "FASTRTPS_DEFAULT_PROFILES_FILE"
DOMAIN_VARIABLE = "ROS_DOMAIN_ID"
#: The nodes of launch/demo.yaml the overrides go to.
WORLD_NODE, ANCHORING_NODE, MISSION_NODE = "world", "anchoring", "mission_demo"


@dataclass(frozen=True)
class RunOptions:
    """How one run is made: seed of the world, matcher (None: the anchoring configuration's),
    deadline (s, None: none), grace period of the nodes' shutdown (s), DDS domain (None: inherit)."""

    seed: int | None = None
    matcher: str | None = None
    deadline: float | None = None
    grace_period: float = 10.0
    domain: int | None = None


def demo_launch(folder: Path, world_file: str | None, options: RunOptions) -> LaunchSpec:
    """launch/demo.yaml for a run whose data go to ``folder``, with the run's overrides."""
    previous = os.environ.get(DATA_VARIABLE)
    os.environ[DATA_VARIABLE] = str(folder)  # the launch file expands it while it is read
    try:
        spec = load_launch_file(find_launch_file(DEMO_LAUNCH))
    finally:
        if previous is None:
            os.environ.pop(DATA_VARIABLE, None)
        else:
            os.environ[DATA_VARIABLE] = previous
    overrides: dict[str, dict[str, Any]] = {WORLD_NODE: {}, MISSION_NODE: {}, ANCHORING_NODE: {}}
    if world_file is not None:
        overrides[WORLD_NODE]["world_file"] = world_file
        overrides[MISSION_NODE]["world_file"] = world_file
    if options.seed is not None:
        overrides[WORLD_NODE]["seed"] = options.seed
    if options.matcher is not None:
        overrides[ANCHORING_NODE]["matcher"] = options.matcher
    spec = with_parameters(spec, {node: values for node, values in overrides.items() if values})
    environment = dict(spec.environment)
    environment[DATA_VARIABLE] = str(folder)
    if FAST_DDS_PROFILE_VARIABLE not in os.environ and FAST_DDS_PROFILE_VARIABLE not in environment:
        environment[FAST_DDS_PROFILE_VARIABLE] = str(config_file("fastdds.xml"))
    if options.domain is not None:
        environment[DOMAIN_VARIABLE] = str(options.domain)
    # The demo is self-contained: its DDS traffic stays on this machine unless told otherwise.
    environment.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", os.environ.get("ROS_AUTOMATIC_DISCOVERY_RANGE",
                                                                          "LOCALHOST"))
    return dataclasses.replace(spec, environment=environment)


def with_parameters(spec: LaunchSpec, values: Mapping[str, Mapping[str, Any]]) -> LaunchSpec:
    """``spec`` with ``values[label]`` appended to the parameters of the node labelled so."""
    labels = {node.label for node in spec.nodes}
    unknown = sorted(set(values) - labels)
    if unknown:
        raise ConfigurationError(f"{spec.source}: no node {unknown} to set parameters of; nodes: {sorted(labels)}")
    nodes = tuple(
        dataclasses.replace(node, parameters=(*node.parameters, dict(values[node.label])))
        if node.label in values else node
        for node in spec.nodes
    )
    return dataclasses.replace(spec, nodes=nodes)


def effective_parameter(spec: LaunchSpec, label: str, name: str) -> Any:
    """The value ``name`` takes in node ``label`` from its parameter files and values (the last
    one that sets it wins); None when none sets it (the node's own default applies)."""
    node = next((node for node in spec.nodes if node.label == label), None)
    if node is None:
        raise ConfigurationError(f"{spec.source}: no node '{label}'")
    value = None
    for parameters in node.parameters:
        if isinstance(parameters, Path):
            document = yaml.safe_load(parameters.read_text(encoding="utf-8")) or {}
            for section in document.values():
                if isinstance(section, Mapping) and name in (section.get("ros__parameters") or {}):
                    value = section["ros__parameters"][name]
        elif name in parameters:
            value = parameters[name]
    return value


class _Tee:
    """Lines to a log file and, optionally, to the terminal too."""

    def __init__(self, log: IO[str], echo: IO[str] | None) -> None:
        self._log, self._echo = log, echo

    def write(self, text: str) -> int:
        self._log.write(text)
        if self._echo is not None:
            self._echo.write(text)
        return len(text)

    def flush(self) -> None:
        self._log.flush()
        if self._echo is not None:
            self._echo.flush()

    def isatty(self) -> bool:
        return False


def launch(spec: LaunchSpec, output: IO[str] | None, grace_period: float, deadline: float | None,
           stop: threading.Event | None = None) -> tuple[LaunchResult, bool]:
    """Run ``spec`` to its end, or stop it at ``deadline`` seconds; Ctrl-C and SIGTERM stop it
    cleanly (and set ``stop``). Returns the result and whether the deadline stopped it."""
    supervisor = Supervisor(spec, output=output, grace_period=grace_period)
    hung = threading.Event()

    def on_deadline() -> None:
        hung.set()
        supervisor.request_stop(f"the deadline of {deadline:g} s passed")

    def on_signal(signal_number: int, _frame: FrameType | None) -> None:
        if stop is not None:
            stop.set()
        supervisor.request_stop(f"received {signal.Signals(signal_number).name}")

    timer = threading.Timer(deadline, on_deadline) if deadline is not None else None
    previous = {number: signal.signal(number, on_signal) for number in (signal.SIGINT, signal.SIGTERM)}
    try:
        if timer is not None:
            timer.daemon = True
            timer.start()
        result = supervisor.run()
    finally:
        if timer is not None:
            timer.cancel()
        for number, handler in previous.items():
            signal.signal(number, handler)
    return result, hung.is_set()


def run_scenario(entry: ScenarioEntry, folder: Path, options: RunOptions, matcher_label: str,
                 echo: IO[str] | None = None, stop: threading.Event | None = None) -> ScenarioRun:
    """One run of ``entry`` with its data and ``launch.log`` in ``folder`` (made, must be empty)."""
    folder.mkdir(parents=True, exist_ok=True)
    spec = demo_launch(folder, entry.world_file, options)
    seed = options.seed if options.seed is not None else 0
    started = time.monotonic()
    with open(folder / "launch.log", "w", encoding="utf-8") as log:
        result, hung = launch(spec, _Tee(log, echo), options.grace_period, options.deadline, stop)
        print(result.summary(), file=log, flush=True)
    wall = time.monotonic() - started
    base = ScenarioRun(entry.name, seed, matcher_label, None, wall_seconds=wall, folder=str(folder))
    if stop is not None and stop.is_set():
        return dataclasses.replace(base, ending=CRASH, note="interrupted")
    scorecard = folder / "report" / "scorecard.json"
    if hung and not scorecard.is_file():  # the report comes last: with it, the deadline only cut the shutdown
        return dataclasses.replace(base, ending=HANG, note=f"not done after the deadline of {options.deadline:g} s")
    try:
        card = json.loads(scorecard.read_text(encoding="utf-8"))
        verdict = judge(card, entry.mission.expect)
    except (OSError, ValueError) as error:
        return dataclasses.replace(base, ending=CRASH, note=f"no scorecard ({error}); launch: {result.stop_reason}; "
                                   f"see {folder / 'launch.log'}")
    return dataclasses.replace(base, verdict=verdict)
