"""Run the real nodes over DDS, fed by the frame player, and record what comes out and what it costs.

The graph is the perception-to-knowledge half of ``sailor launch sailor`` without the detector:
``frame_player`` (this harness's camera, ground-truth detections) -> ``percept_generator`` ->
``anchoring`` -> ``knowledge_base``, each a process started by the project's launcher with its
shipped configuration, all in one namespace. A probe node in this process records every
PerceptArray, AnchorArray and AnchorEventArray with the stamps needed to correlate them to the
frame they came from (see :mod:`harness.pipeline_analysis`), and a sampler thread reads each
process's resident memory and CPU time from /proc. ROS is imported here, so only the pipeline
benchmarks and tests import this module.
"""

from __future__ import annotations

import io
import json
import os
import signal
import struct
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import rclpy
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from harness.frame_player import Phase
from merlin2_sailor.errors import SailorError
from merlin2_sailor.launcher import LaunchResult, LaunchSpec, NodeSpec, Supervisor
from merlin2_sailor.launcher.command import resolve_executable
from merlin2_sailor.resources import config_file
from merlin2_sailor.ros.background_spinner import BackgroundSpinner
from merlin2_sailor.ros.qos import EVENTS
from merlin2_sailor_interfaces.msg import AnchorArray, AnchorEventArray, DetectionArray, PerceptArray

PLAYER_SCRIPT = Path(__file__).resolve().parent / "frame_player.py"
PLAYER_LABEL = "frame_player"
#: The nodes whose memory and CPU are sampled, by launch label.
NODE_LABELS = ("percept_generator", "anchoring", "knowledge_base")
BENCH_DOMAIN_ID = "101"  # the highest of the IDs ROS 2 advises on Linux; the tests use 1..100
#: Lines of the nodes' output repeated on the console: progress and anything that went wrong.
_NOTABLE = ("[launch]", f"[{PLAYER_LABEL}]", "WARN", "ERROR", "Traceback", "percept arrays in the last")

Echo = Callable[[str], None]


class PipelineError(SailorError):
    """The graph did not run: a node failed to start, or the player never saw the graph."""


@dataclass(frozen=True)
class PipelineConfig:
    objects: int
    phases: tuple[Phase, ...]
    namespace: str = "bench"
    sample_period: float = 0.5  # seconds between two memory / CPU samples
    report_period: float = 5.0  # seconds between two statistics lines of the percept generator
    drain_seconds: float = 1.5
    graph_timeout: float = 60.0  # how long the player waits for the graph before giving up
    #: The real detector node between the camera and the percept generator (objects show real
    #: photos), instead of ground-truth detections from the player.
    detector: bool = False
    #: Anchoring and detector parameters over the shipped configuration (e.g. the matcher, the runtime).
    anchoring_parameters: tuple[tuple[str, object], ...] = ()
    detector_parameters: tuple[tuple[str, object], ...] = ()
    percept_parameters: tuple[tuple[str, object], ...] = ()

    @property
    def node_labels(self) -> tuple[str, ...]:
        return NODE_LABELS + (("detector",) if self.detector else ())

    @property
    def playing_seconds(self) -> float:
        return sum(phase.seconds for phase in self.phases)


@dataclass
class Recording:
    """Everything a run produced, as plain data (times in integer nanoseconds of the wall clock)."""

    config: PipelineConfig
    played: dict[str, Any]  # the player's record: phases, frames [stamp ns, phase, measured], publish cost
    percepts: list[tuple[int, int, int]]  # (received, header stamp, percepts)
    anchors: list[tuple[int, int, int, int]]  # (received, header stamp = publication, newest last_seen, anchors)
    events: list[tuple[int, tuple[int, ...]]]  # (header stamp = publication, the events' stamps)
    samples: list[tuple[int, dict[str, tuple[float, float]]]]  # (time, {label: (RSS MB, CPU seconds)})
    pids: dict[str, int]
    outcomes: list[dict[str, Any]]
    log: list[str] = field(default_factory=list)
    detections: list[tuple[int, int]] = field(default_factory=list)  # (received, header stamp), with the detector

    @property
    def ended_cleanly(self) -> bool:
        return all(outcome["clean"] for outcome in self.outcomes)


def isolate_ros_domain() -> None:
    """Keep the benchmark's graph to itself: its own domain, discovery on this host only.

    Also makes SIGTERM end the benchmark like Ctrl-C, so that it still stops the nodes it started.
    """
    os.environ["ROS_DOMAIN_ID"] = BENCH_DOMAIN_ID
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    signal.signal(signal.SIGTERM, signal.default_int_handler)


def stamp_ns(stamp: Any) -> int:
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def percept_array_stamp_and_size(raw: bytes) -> tuple[int, int]:
    """Header stamp (ns) and number of percepts of a serialized PerceptArray, its crops left unread.

    Deserialising 50 percepts with their crops costs about a millisecond of Python per message,
    which the probe would take from the nodes it measures. In CDR, after the 4-byte encapsulation:
    the header's stamp (int32 sec, uint32 nanosec), its frame_id (uint32 length, bytes with NUL),
    then, aligned to 4, the length of the percepts sequence.
    """
    order = "<" if raw[1] == 1 else ">"  # CDR_LE / CDR_BE
    seconds, nanoseconds, frame_id_length = struct.unpack_from(f"{order}iII", raw, 4)
    offset = 16 + frame_id_length
    offset += -(offset - 4) % 4  # CDR aligns relative to the end of the encapsulation
    (count,) = struct.unpack_from(f"{order}I", raw, offset)
    return seconds * 1_000_000_000 + nanoseconds, count


class Probe:
    """A node of this process recording the graph's outputs; callbacks only append tuples."""

    def __init__(self, namespace: str) -> None:
        self.percepts: list[tuple[int, int, int]] = []
        self.anchors: list[tuple[int, int, int, int]] = []
        self.events: list[tuple[int, tuple[int, ...]]] = []
        self.detections: list[tuple[int, int]] = []  # (received, header stamp) of the detector's DetectionArrays
        self._spinner = BackgroundSpinner("bench-probe")
        node = self._spinner.add_node(
            rclpy.create_node("bench_probe", namespace=f"/{namespace}", context=self._spinner.context))
        deep_best_effort = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=100,
                                      reliability=ReliabilityPolicy.BEST_EFFORT)
        deep_latched = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=100, reliability=ReliabilityPolicy.RELIABLE,
                                  durability=DurabilityPolicy.TRANSIENT_LOCAL)
        node.create_subscription(PerceptArray, "percepts", self._on_percepts, deep_best_effort, raw=True)
        node.create_subscription(AnchorArray, "anchors", self._on_anchors, deep_latched)
        node.create_subscription(AnchorEventArray, "anchor_events", self._on_events, EVENTS)
        node.create_subscription(DetectionArray, "detections", self._on_detections, deep_best_effort)

    def _on_detections(self, message: DetectionArray) -> None:
        self.detections.append((time.time_ns(), stamp_ns(message.header.stamp)))

    def _on_percepts(self, raw: bytes) -> None:
        received = time.time_ns()
        self.percepts.append((received, *percept_array_stamp_and_size(raw)))

    def _on_anchors(self, message: AnchorArray) -> None:
        newest = max((stamp_ns(anchor.last_seen) for anchor in message.anchors), default=0)
        self.anchors.append((time.time_ns(), stamp_ns(message.header.stamp), newest, len(message.anchors)))

    def _on_events(self, message: AnchorEventArray) -> None:
        self.events.append((stamp_ns(message.header.stamp), tuple(stamp_ns(e.stamp) for e in message.events)))

    def close(self) -> None:
        self._spinner.close()


# --- processes: who is who, and what they cost -----------------------------------------------------


def read_resources(pid: int) -> tuple[float, float] | None:
    """(resident memory in MB, CPU seconds used) of a process, or None once it has gone."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return None
    rss_kb = next((int(line.split()[1]) for line in status.splitlines() if line.startswith("VmRSS:")), 0)
    fields = stat.rsplit(")", 1)[1].split()  # after the command name, which may hold spaces
    ticks = int(fields[11]) + int(fields[12])  # utime + stime (fields 14 and 15 of proc(5))
    return rss_kb / 1024.0, ticks / os.sysconf("SC_CLK_TCK")


def child_processes() -> dict[int, list[str]]:
    """This process's children and their command lines."""
    children = {}
    me = os.getpid()
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            parent = int((entry / "stat").read_text().rsplit(")", 1)[1].split()[1])
            if parent == me:
                children[int(entry.name)] = (entry / "cmdline").read_bytes().decode(errors="replace").split("\0")
        except (OSError, IndexError, ValueError):
            continue
    return children


def find_pids(tokens: dict[str, str], timeout: float) -> dict[str, int]:
    """The pid of each label's process: the child whose command line holds the label's token."""
    found: dict[str, int] = {}
    deadline = time.monotonic() + timeout
    while len(found) < len(tokens) and time.monotonic() < deadline:
        for pid, command in child_processes().items():
            for label, token in tokens.items():
                if label not in found and token in command:
                    found[label] = pid
        time.sleep(0.1)
    return found


class ResourceSampler:
    """Samples each watched process's RSS and CPU time every ``period`` seconds on a thread."""

    def __init__(self, pids: dict[str, int], period: float) -> None:
        self.samples: list[tuple[int, dict[str, tuple[float, float]]]] = []
        self._pids, self._period = pids, period
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="bench-sampler", daemon=True)

    def start(self) -> None:
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=5.0)

    def _run(self) -> None:
        while not self._stop.is_set():
            sample = {label: value for label, pid in self._pids.items() if (value := read_resources(pid))}
            if sample:
                self.samples.append((time.time_ns(), sample))
            self._stop.wait(self._period)


class NodeLog(io.TextIOBase):
    """The launcher's output stream: keeps every line, repeats the notable ones on the console."""

    def __init__(self, echo: Echo) -> None:
        self.lines: list[str] = []
        self._echo = echo

    def write(self, text: str) -> int:
        for line in text.splitlines():
            self.lines.append(line)
            if any(mark in line for mark in _NOTABLE):
                self._echo(line)
        return len(text)

    def isatty(self) -> bool:
        return False


# --- the run ---------------------------------------------------------------------------------------


def launch_spec(config: PipelineConfig, folder: Path, frames_file: Path) -> LaunchSpec:
    namespace = config.namespace.strip("/")
    player_arguments = [str(PLAYER_SCRIPT), "--objects", str(config.objects), "--output", str(frames_file),
                        "--drain", str(config.drain_seconds)]
    for phase in config.phases:
        player_arguments += ["--phase", phase.argument()]
    if config.detector:
        player_arguments.append("--detector")
    detector = (NodeSpec("detector", namespace=namespace, parameters=(
        config_file("detector.yaml"), dict(config.detector_parameters))),) if config.detector else ()
    nodes = detector + (
        NodeSpec("knowledge_base", namespace=f"{namespace}/merlin2", parameters=(config_file("knowledge_base.yaml"),)),
        NodeSpec("anchoring", namespace=namespace, parameters=(
            config_file("anchoring.yaml"),
            {"state_folder": str(folder / "anchoring"), "knowledge_base": f"ros:///{namespace}/merlin2",
             **dict(config.anchoring_parameters)})),
        NodeSpec("percept_generator", namespace=namespace, parameters=(
            config_file("percept_generator.yaml"),
            {"report_period": config.report_period, **dict(config.percept_parameters)})),
        # By name, so the launcher finds this venv's interpreter (a path would be resolved past its symlink).
        NodeSpec(Path(sys.executable).name, name=PLAYER_LABEL, namespace=namespace, arguments=tuple(player_arguments)),
    )
    environment = {"ROS_LOG_DIR": str(folder / "ros_logs"), "RCUTILS_COLORIZED_OUTPUT": "0"}
    return LaunchSpec(nodes, environment)


def run_pipeline(config: PipelineConfig, echo: Echo = print) -> Recording:
    """Start the graph, play every phase, stop the graph; return what was recorded.

    Raises PipelineError when the graph did not run (a node crashed at start, or the player gave up
    waiting for it), with the end of the nodes' output.
    """
    # The probe needs the same Fast DDS profile as the nodes (shared memory, short leases).
    os.environ.setdefault("FASTRTPS_DEFAULT_PROFILES_FILE", str(config_file("fastdds.xml")))
    with tempfile.TemporaryDirectory(prefix="sailor-bench-") as scratch:
        folder = Path(scratch)
        frames_file = folder / "frames.json"
        spec = launch_spec(config, folder, frames_file)
        log = NodeLog(echo)
        supervisor = Supervisor(spec, output=log, grace_period=10.0, colour=False)
        outcome: list[LaunchResult] = []
        probe = Probe(config.namespace)
        safety = config.playing_seconds + config.drain_seconds + config.graph_timeout + 30.0
        runner = threading.Thread(target=lambda: outcome.append(supervisor.run(duration=safety)),
                                  name="bench-launch", daemon=True)
        runner.start()
        tokens = {label: resolve_executable(label) for label in config.node_labels}
        tokens[PLAYER_LABEL] = str(PLAYER_SCRIPT)
        pids = find_pids(tokens, timeout=30.0)
        sampler = ResourceSampler({label: pid for label, pid in pids.items()}, config.sample_period)
        sampler.start()
        try:
            runner.join(timeout=safety + 60.0)
        finally:
            supervisor.request_stop("the benchmark ended")
            runner.join(timeout=30.0)
            sampler.stop()
            probe.close()
        result = outcome[0] if outcome else None
        outcomes = [{"label": o.label, "pid": o.pid, "return_code": o.return_code, "ending": o.ending.value,
                     "clean": o.clean} for o in (result.outcomes if result else ())]
        if result is not None:
            echo(result.summary())
        if not frames_file.is_file():
            tail = "\n".join(log.lines[-40:])
            raise PipelineError(f"the pipeline did not run (no frames were played); the nodes said:\n{tail}")
        played = json.loads(frames_file.read_text())
    return Recording(config, played, probe.percepts, probe.anchors, probe.events, sampler.samples, pids, outcomes,
                     log.lines, probe.detections)


def phases_of(specs: Sequence[tuple[str, float, float, float]]) -> tuple[Phase, ...]:
    return tuple(Phase(label, rate, seconds, settle) for label, rate, seconds, settle in specs)
