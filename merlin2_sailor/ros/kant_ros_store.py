"""KantRosStore: MERLIN2's knowledge base as MERLIN2 runs it, KANT's own node, through KANT's ROS 2 DAOs.

In a MERLIN2 deployment the knowledge base is KANT's ``knowledge_base_node`` (``kant_knowledge_base``),
and every MERLIN2 component reaches it through KANT's ROS 2 DAO family. ``kant+ros:///namespace``
opens the same family here, on a node of this store's own (its own context and executor thread, so
its blocking calls never wait on a caller's executor), in the namespace where KANT's node serves
``get_types``, ``update_type`` and the rest (MERLIN2 launches it under ``/merlin2``).

KANT's DAOs wait for a service, and for its answer, without a deadline. This store gives every
exchange one: it first checks that KANT's node is there, then runs the exchange on a worker thread
and gives up after ``timeout`` seconds per request, raising KnowledgeError instead of hanging.
A thread left waiting on a node that died mid-call is abandoned: it holds nothing of the store's,
and, a daemon, it does not keep the process from exiting.

Over DDS a service can be listed before its answers can reach this client (the server's reply
writer has not yet matched the client's reader): the request is served, the reply is lost, and
KANT's DAO waits forever (measured in CI: a store opened on a node that had just started never
got its first read). So a read is asked again within its deadline (READ_ATTEMPTS,
READ_ATTEMPT_SECONDS); a write is not repeated, since KANT would apply it twice.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Sequence
from typing import Any, TypeVar

import rclpy

from merlin2_sailor.errors import KnowledgeError
from merlin2_sailor.knowledge.changes import ChangeEvent
from merlin2_sailor.knowledge.kant_store import KantStore, import_kant_module
from merlin2_sailor.knowledge.store import DEFAULT_TIMEOUT_SECONDS
from merlin2_sailor.ros.background_spinner import BackgroundSpinner

SCHEME = "kant+ros://"
PROBE_SERVICE = "get_types"
"""A service KANT's knowledge-base node always serves: its presence says the node is up."""
REQUESTS_PER_READ = 5
"""A reload asks KANT for each of its five kinds."""
READ_ATTEMPTS = 3
"""A read is asked at least this many times within its deadline before the store gives up..."""
READ_ATTEMPT_SECONDS = 10.0
"""...and again every this many seconds at most (a lost reply never comes; KANT answers in milliseconds)."""

Result = TypeVar("Result")


class KantRosStore(KantStore):
    """KANT's ROS 2 DAO family over a node of this store's own, with a deadline on every exchange."""

    def __init__(self, namespace: str = "/", timeout: float = DEFAULT_TIMEOUT_SECONDS) -> None:
        dao_factory_module = import_kant_module("kant_dao.dao_factory")
        service_type = import_kant_module("std_srvs.srv").Empty
        self._timeout = timeout
        self._namespace = "/" + namespace.strip("/")
        self._spinner = BackgroundSpinner("kant-store")
        try:
            node = self._spinner.add_node(
                rclpy.create_node("sailor_kant_store", namespace=self._namespace, context=self._spinner.context)
            )
            self._probe = node.create_client(service_type, "delete_all_types")  # never called: presence only
            families = dao_factory_module.DaoFamilies
            factory = dao_factory_module.DaoFactoryMethod().create_dao_factory(families.ROS2, node=node)
            super().__init__(factory)
        except BaseException:
            self._close_database()
            raise

    @classmethod
    def from_location(cls, location: str, timeout: float = DEFAULT_TIMEOUT_SECONDS) -> KantRosStore:
        """``kant+ros:///merlin2``: KANT's node in ``/merlin2``; ``kant+ros://`` alone: the root."""
        return cls(namespace=location.removeprefix(SCHEME) or "/", timeout=timeout)

    def _load(self) -> list:
        return self._with_deadline(super()._load, REQUESTS_PER_READ, retried=True)

    def _persist(self, events: Sequence[ChangeEvent]) -> None:
        # A save may first read what it refers to; allow two requests per change.
        self._with_deadline(lambda: super(KantRosStore, self)._persist(events), 2 * len(events) + 1)

    def _with_deadline(self, exchange: Callable[[], Result], requests: int, retried: bool = False) -> Result:
        """Run ``exchange`` within ``timeout`` seconds per request; a ``retried`` one (a read) is
        asked again, in tries of READ_ATTEMPT_SECONDS at most, until that deadline."""
        deadline = self._timeout * requests
        ends = time.monotonic() + deadline
        while True:
            remaining = ends - time.monotonic()
            if remaining <= 0:
                raise KnowledgeError(f"KANT's knowledge base in {self._namespace} did not answer within {deadline:g} s")
            answered, value = self._attempt(
                exchange, min(remaining, READ_ATTEMPT_SECONDS, deadline / READ_ATTEMPTS) if retried else remaining)
            if answered:
                return value

    def _attempt(self, exchange: Callable[[], Result], deadline: float) -> tuple[bool, Result | None]:
        """(True, result) if the exchange ended within ``deadline``, (False, None) if not; its error is raised."""
        if not self._spinner.context.ok():
            raise KnowledgeError("the ROS context of the KANT store has shut down")
        if not self._probe.wait_for_service(timeout_sec=self._timeout):
            raise KnowledgeError(
                f"KANT's knowledge base is not reachable: {self._namespace.rstrip('/')}/{PROBE_SERVICE} did not "
                f"appear within {self._timeout:g} s; is kant_knowledge_base's node running in {self._namespace}?"
            )
        outcome: list[tuple[bool, Any]] = []

        def run() -> None:
            try:
                outcome.append((True, exchange()))
            except BaseException as error:  # handed to the caller below
                outcome.append((False, error))

        # A daemon thread per exchange: one stuck in KANT's deadline-less call is left behind
        # without keeping the process from exiting (a pool's threads are joined at exit).
        worker = threading.Thread(target=run, name="kant-store-exchange", daemon=True)
        worker.start()
        worker.join(deadline)
        if not outcome:
            return False, None
        succeeded, value = outcome[0]
        if not succeeded:
            raise value
        return True, value

    def _close_database(self) -> None:
        self._spinner.close()

