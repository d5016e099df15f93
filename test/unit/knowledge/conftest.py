"""Fixtures shared by the knowledge tests: stores of every kind, example scenes and anchors.

The MongoDB store is tested against nx-27017, a MongoDB wire-protocol server backed by SQLite,
started once per session on a free loopback port with its data in a temporary directory.
"""

import importlib.util
import socket
import subprocess
import sys
import time
import uuid
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

from merlin2_sailor.knowledge import (
    Condition,
    Effect,
    KnowledgeBase,
    KnowledgeItem,
    Parameter,
    PddlAction,
    PddlObject,
    PddlType,
    Predicate,
    Proposition,
)
from merlin2_sailor.ros.stores import open_store

SERVER_START_TIMEOUT_SECONDS = 15.0


def _free_loopback_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


@pytest.fixture(scope="session")
def mongo_server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    """The base URI (``mongodb://127.0.0.1:PORT``) of a private nx-27017 server."""
    if importlib.util.find_spec("nx_27017") is None:
        pytest.skip("nx-27017 is not installed; run the project's setup to test the Mongo store")
    directory = tmp_path_factory.mktemp("nx_27017")
    port = _free_loopback_port()
    log_file = directory / "server.log"
    server = subprocess.Popen(
        [
            sys.executable, "-m", "nx_27017.nx_27017",
            "--host", "127.0.0.1", "--port", str(port),
            "--data-dir", str(directory / "data"),
            "--log-file", str(log_file), "--pid-file", str(directory / "server.pid"),
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )  # fmt: skip
    try:
        _wait_until_listening(server, port, log_file)
        yield f"mongodb://127.0.0.1:{port}"
    finally:
        server.terminate()
        try:
            server.wait(timeout=5)
        except subprocess.TimeoutExpired:
            server.kill()
            server.wait()


def _wait_until_listening(server: subprocess.Popen, port: int, log_file: Path) -> None:
    deadline = time.monotonic() + SERVER_START_TIMEOUT_SECONDS
    while time.monotonic() < deadline:
        if server.poll() is not None:
            break
        try:
            socket.create_connection(("127.0.0.1", port), timeout=0.2).close()
            return
        except OSError:
            time.sleep(0.02)
    log = log_file.read_text() if log_file.exists() else "(no log)"
    pytest.fail(f"nx-27017 did not start on port {port}:\n{log[-2000:]}")


def _location(kind: str, tmp_path: Path, request: pytest.FixtureRequest) -> str:
    if kind in ("kant_mongo", "kant_ros"):
        return request.getfixturevalue(f"{kind}_location")
    if kind == "memory":
        return "memory"
    if kind == "sqlite":
        return f"sqlite://{tmp_path / 'knowledge.db'}"
    if kind == "ros":
        return request.getfixturevalue("knowledge_base_node")
    server = request.getfixturevalue("mongo_server")
    return f"{server}/knowledge_{uuid.uuid4().hex}"


@pytest.fixture
def knowledge_base_node(tmp_path: Path) -> Iterator[str]:
    """A knowledge_base node over a SQLite store, spinning in this process in a ROS context of
    its own, under a namespace of this test's own; yields its ``ros://`` location. The client
    that the test opens there talks to it over DDS like any other process would."""
    from merlin2_sailor.ros.background_spinner import BackgroundSpinner
    from merlin2_sailor.ros.knowledge_base_node import KnowledgeBaseNode

    namespace = f"/kb_{uuid.uuid4().hex[:12]}"
    spinner = BackgroundSpinner("knowledge-base-node")
    spinner.add_node(KnowledgeBaseNode(
        store=open_store(f"sqlite://{tmp_path / 'served.db'}"), context=spinner.context, namespace=namespace
    ))
    try:
        yield f"ros://{namespace}"
    finally:
        spinner.close()


@pytest.fixture
def kant_mongo_location(upstream_stack, monkeypatch: pytest.MonkeyPatch) -> str:
    """Real KANT's MongoDB family over mongomock, on a database of this test's own.

    KANT's factory connects with mongoengine.connect(host=uri); it is given mongomock's client
    class, over one in-memory server for the whole test, so a store opened again finds the data.
    nx-27017 cannot serve KANT: it refuses the exact array match KANT queries propositions with.
    """
    upstream_stack("kant_dao", "mongoengine", "mongomock")
    import functools

    import kant_dao.dao_factory.dao_factories.mongo_dao_factory as mongo_dao_factory
    import mongoengine
    import mongomock
    import mongomock.store

    server = mongomock.store.ServerStore()

    def mongomock_client(*arguments, **settings):
        return mongomock.MongoClient(*arguments, _store=server, **settings)

    monkeypatch.setattr(mongo_dao_factory, "connect",
                        functools.partial(mongoengine.connect, mongo_client_class=mongomock_client))
    return f"kant+mongodb://localhost/kant_{uuid.uuid4().hex}"


@pytest.fixture
def kant_ros_location(kant_node) -> str:
    return kant_node.location


@pytest.fixture(params=["memory", "sqlite", "mongo", pytest.param("ros", marks=pytest.mark.ros),
                        "kant_mongo", pytest.param("kant_ros", marks=pytest.mark.ros)])
def store_location(request: pytest.FixtureRequest, tmp_path: Path) -> str:
    """Where a fresh store of each kind lives; open it again to test persistence."""
    return _location(request.param, tmp_path, request)


@pytest.fixture(params=["sqlite", "mongo"])
def persistent_location(request: pytest.FixtureRequest, tmp_path: Path) -> str:
    """Like ``store_location``, for the stores that outlive the process."""
    return _location(request.param, tmp_path, request)


@pytest.fixture
def store(store_location: str) -> Iterator[KnowledgeBase]:
    with open_store(store_location) as opened:
        yield opened


@pytest.fixture
def memory_store() -> Iterator[KnowledgeBase]:
    with open_store("memory") as opened:
        yield opened


@pytest.fixture
def recorded_events(store: KnowledgeBase) -> list:
    """Every batch of events the store publishes, in order."""
    batches: list = []
    store.subscribe(batches.append)
    return batches


def kitchen_scene() -> list[KnowledgeItem]:
    """A small MERLIN2 world: a robot, two waypoints, a cup and the navigation action."""
    return [
        PddlType("robot"),
        PddlType("wp"),
        PddlType("container"),
        PddlType("cup", "container"),
        Predicate("robot_at", ("robot", "wp")),
        Predicate("object_at", ("object", "wp")),
        Predicate("filled", ("container",)),
        PddlObject("rb1", "robot"),
        PddlObject("kitchen", "wp"),
        PddlObject("living_room", "wp"),
        PddlObject("cup_1", "cup"),
        Proposition("robot_at", ("rb1", "kitchen")),
        Proposition("object_at", ("cup_1", "kitchen")),
        Proposition("robot_at", ("rb1", "living_room"), is_goal=True),
        PddlAction(
            "navigation",
            parameters=(Parameter("r", "robot"), Parameter("origin", "wp"), Parameter("to", "wp")),
            conditions=(Condition("robot_at", ("r", "origin"), "at start"),),
            effects=(
                Effect("robot_at", ("r", "origin"), "at start", is_negative=True),
                Effect("robot_at", ("r", "to"), "at end"),
            ),
        ),
    ]


@pytest.fixture
def scene() -> list[KnowledgeItem]:
    return kitchen_scene()


@dataclass
class ExampleAnchor:
    """Shaped like the anchoring layer's Anchor, as far as grounding reads it."""

    symbol: str
    class_name: str
    position: np.ndarray
    state: str = "confirmed"
    visible: bool = True
    size: np.ndarray | None = field(default=None)


AnchorFactory = Callable[..., ExampleAnchor]


@pytest.fixture
def make_anchor() -> AnchorFactory:
    """Build an anchor at (x, y) on the floor: ``make_anchor("cup_1", "cup", 0.5, 0.0)``."""

    def build(symbol: str, class_name: str, x: float, y: float, **attributes) -> ExampleAnchor:
        return ExampleAnchor(symbol, class_name, np.array([x, y, 0.0]), **attributes)

    return build
