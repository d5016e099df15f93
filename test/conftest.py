"""Test-wide set-up: isolate ROS traffic to this run, and offer a probe into the ROS graph.

The environment is set before any test imports rclpy: DDS discovery stays on loopback, each run
gets its own ROS_DOMAIN_ID, locked while it runs (so parallel runs on one machine never see each
other's nodes), logs go to a temporary folder, and Fast DDS uses the project's profile, as
``sailor launch`` does.
Child processes started by the tests inherit all of it.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
import uuid
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

from merlin2_sailor.inference.model_cache import cache_folder
from merlin2_sailor_demos.dds_domains import DOMAINS, claimed_domain

REPOSITORY_ROOT = Path(__file__).resolve().parent.parent

os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"


def _worker_index() -> int | None:
    """This process's pytest-xdist worker number (``make test`` runs two), None outside one."""
    worker = os.environ.get("PYTEST_XDIST_WORKER", "")
    return int(worker[2:]) if worker.startswith("gw") and worker[2:].isdigit() else None


# One ROS domain per run, and one per worker within it: the workers inherit the controller's
# domain (set when it loaded this file) and step off it, so two runs, or two workers, never meet.
# Each holds a lock on its domain for the life of its process, as every run of `sailor demo`
# does (merlin2_sailor_demos.dds_domains), so neither another test run nor a demo started by a
# test (or beside the tests) lands in it.
if "ROS_DOMAIN_ID" not in os.environ or _worker_index() is not None:
    _inherited = os.environ.get("ROS_DOMAIN_ID", "")
    _first = (int(_inherited) - 1 + _worker_index() + 1) if _inherited.isdigit() else os.getpid()
    _DOMAIN_CLAIM = claimed_domain(DOMAINS, _first)
    os.environ["ROS_DOMAIN_ID"] = str(_DOMAIN_CLAIM.__enter__())  # released when the process ends
os.environ.setdefault("ROS_LOG_DIR", tempfile.mkdtemp(prefix="sailor-test-ros-logs-"))
os.environ.setdefault("FASTRTPS_DEFAULT_PROFILES_FILE", str(REPOSITORY_ROOT / "config" / "fastdds.xml"))
os.environ.setdefault("RCUTILS_COLORIZED_OUTPUT", "0")
# Exported models are named by a hash of what they were exported from, so the run may share the
# user's model cache (set-up fills it): it cannot read a stale model. Fixed before HOME moves.
os.environ.setdefault("SAILOR_MODEL_CACHE", str(cache_folder()))
# Nodes keep state under ~ (e.g. ~/.sailor/anchoring): tests must neither read a user's state
# nor leave theirs behind, so this run gets a home of its own.
os.environ["HOME"] = tempfile.mkdtemp(prefix="sailor-test-home-")

# With SAILOR_UPSTREAM, scripts/upstream_env.sh puts the real YASMIN on the path; the behaviours
# keep running on the project's own implementation of its API unless a run asks for the real one.
os.environ.setdefault("SAILOR_STATE_MACHINES", "local")

UPSTREAM_VARIABLE = "SAILOR_UPSTREAM"


def require_upstream(*modules: str) -> None:
    """Skip, saying why, when the real MERLIN2 stack is not set up; fail when it is set up but broken.

    ``make test`` sources scripts/upstream_env.sh, which builds the stack from the source checkouts
    that ``SAILOR_UPSTREAM`` names (``.ci/run`` sets it to ../shared/upstream where that exists).
    """
    import importlib

    if not os.environ.get(UPSTREAM_VARIABLE):
        pytest.skip(f"{UPSTREAM_VARIABLE} is unset: the tests against the real MERLIN2 stack need it "
                    f"(run: {UPSTREAM_VARIABLE}=../shared/upstream make test)")
    for module in modules:
        try:
            importlib.import_module(module)
        except ImportError as error:
            pytest.fail(f"{UPSTREAM_VARIABLE}={os.environ[UPSTREAM_VARIABLE]} is set but {module} does not import "
                        f"({error}); run the tests through `make test`, which sources scripts/upstream_env.sh")


@pytest.fixture(scope="session")
def upstream_stack() -> Callable[..., None]:
    """:func:`require_upstream`, for tests that need the real MERLIN2 stack."""
    return require_upstream


KANT_NODE_MODULE = "kant_knowledge_base.knowledge_base_node_main"
"""KANT's knowledge-base node, MERLIN2's knowledge base, as ``ros2 run kant_knowledge_base`` starts it."""
KANT_START_SECONDS = 30.0
KANT_STOP_SECONDS = 3.0


@dataclass
class KantNode:
    """KANT's knowledge-base node running as a process, and where a ``kant+ros`` store finds it."""

    location: str
    process: subprocess.Popen


@pytest.fixture
def start_kant_node(upstream_stack) -> Iterator[Callable[[str], KantNode]]:
    """Start KANT's own knowledge-base node, unmodified, as a process in a given namespace."""
    upstream_stack("kant_knowledge_base", "kant_msgs.srv", "simple_node")
    started: list[subprocess.Popen] = []

    def start(namespace: str) -> KantNode:
        process = subprocess.Popen(
            [sys.executable, "-m", KANT_NODE_MODULE, "--ros-args", "-r", f"__ns:={namespace}"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL,
        )
        started.append(process)
        node = KantNode(f"kant+ros://{namespace}", process)
        # Ready when a KANT store can read it: the tests' own deadlines then measure the tests,
        # not the node's start on a busy machine.
        from merlin2_sailor.ros.stores import open_store

        with open_store(node.location, timeout=KANT_START_SECONDS):
            pass
        return node

    yield start
    for process in started:
        process.send_signal(signal.SIGINT)  # what ros2 launch sends; KANT's node ignores SIGTERM
        try:
            # Most stop within a second; one in five outlives SIGINT for good (measured: 10 s each).
            process.wait(timeout=KANT_STOP_SECONDS)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


@pytest.fixture
def kant_node(start_kant_node) -> KantNode:
    """KANT's knowledge-base node in a namespace of this test's own."""
    return start_kant_node(f"/kant_{uuid.uuid4().hex[:12]}")


# --- Fixtures for tests that talk to real nodes over DDS -----------------------------------
# ros_probe gives a node spinning in a background thread of its own context and guarantees the
# teardown (executor shut down, thread joined, node destroyed, context shut down): an executor
# left spinning at exit aborts the interpreter. node_process starts console scripts as real
# processes and stops them with SIGINT.


GRAPH_TIMEOUT_SECONDS = 20.0


class RosProbe:
    """A node of the test's own, to look into the graph and exchange messages with nodes."""

    def __init__(self) -> None:
        import rclpy

        from merlin2_sailor.ros.background_spinner import BackgroundSpinner

        self._spinner = BackgroundSpinner("test-probe")
        self.context = self._spinner.context
        self.node = self._spinner.add_node(rclpy.create_node(f"test_probe_{os.getpid()}", context=self.context))

    def node_names(self) -> set[str]:
        """Fully qualified names of the nodes currently in the graph."""
        return {
            f"{namespace.rstrip('/')}/{name}"
            for name, namespace in self.node.get_node_names_and_namespaces()
        }

    def wait_for(self, condition: Callable[[], bool], timeout: float = GRAPH_TIMEOUT_SECONDS) -> bool:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if condition():
                return True
            time.sleep(0.05)
        return condition()

    def wait_for_node(self, full_name: str, timeout: float = GRAPH_TIMEOUT_SECONDS) -> bool:
        return self.wait_for(lambda: full_name in self.node_names(), timeout)

    def collect(self, message_type: Any, topic: str, count: int, qos: Any,
                timeout: float = GRAPH_TIMEOUT_SECONDS) -> list[Any]:
        """Subscribe to ``topic`` and return the first ``count`` messages (fewer on timeout)."""
        received: list[Any] = []
        with self.listener() as listener:
            listener.create_subscription(message_type, topic, received.append, qos)
            self.wait_for(lambda: len(received) >= count, timeout)
        return received[:count]

    @contextmanager
    def listener(self) -> Iterator[Any]:
        """A node of its own for subscriptions a test makes and drops, spun on a thread of its own
        and destroyed only after that thread has stopped. Not the probe's node: a subscription
        destroyed while an executor builds its wait set raises rclpy's InvalidHandle on the
        executor's thread and ends it, and the probe would go deaf for the rest of the test."""
        import rclpy
        from rclpy.executors import SingleThreadedExecutor

        node = rclpy.create_node(f"test_listener_{uuid.uuid4().hex[:8]}", context=self.context)
        executor = SingleThreadedExecutor(context=self.context)
        executor.add_node(node)
        spinning = threading.Thread(target=executor.spin, name="test-listener", daemon=True)
        spinning.start()
        try:
            yield node
        finally:
            executor.shutdown()
            spinning.join(timeout=5.0)
            node.destroy_node()

    def close(self) -> None:
        self._spinner.close()


@pytest.fixture
def ros_probe() -> Iterator[RosProbe]:
    probe = RosProbe()
    try:
        yield probe
    finally:
        probe.close()


def scripts_directory() -> Path:
    return Path(sys.executable).parent


@dataclass
class NodeProcess:
    """A node started as a real process; stop() sends SIGINT and returns the exit code."""

    process: subprocess.Popen[str]
    output: list[str] = field(default_factory=list)

    def stop(self, timeout: float = 15.0) -> int:
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
        try:
            out, _ = self.process.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.process.kill()
            out, _ = self.process.communicate()
        self.output.append(out or "")
        return self.process.returncode

    @property
    def text(self) -> str:
        return "".join(self.output)


@pytest.fixture
def node_process() -> Iterator[Callable[..., NodeProcess]]:
    """Start console scripts of this venv (``node_process('rgbd_player', '--ros-args', ...)``)."""
    started: list[NodeProcess] = []

    def start(executable: str, *arguments: str) -> NodeProcess:
        process = subprocess.Popen(
            [str(scripts_directory() / executable), *arguments],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, text=True,
            env={**os.environ, "PYTHONUNBUFFERED": "1"},
        )
        handle = NodeProcess(process)
        started.append(handle)
        return handle

    yield start
    for handle in started:
        handle.stop()
