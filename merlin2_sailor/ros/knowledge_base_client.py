"""RemoteKnowledgeBase: the KnowledgeBase port implemented over the knowledge_base node's services.

Components written against :class:`~merlin2_sailor.knowledge.store.KnowledgeBase` use the
knowledge-base node through this class without knowing it is remote:
``merlin2_sailor.ros.stores.open_store("ros:///merlin2")`` returns one. It runs its own ROS
context, node and executor thread, so its blocking calls can be made from anywhere, including
another node's callbacks, without deadlocking that node's executor.

A knowledge base that does not answer raises KnowledgeError naming the service and the timeout;
callers log it and try again later, and nothing they hold is lost.
"""

from __future__ import annotations

import threading
import uuid
from collections.abc import Hashable, Iterable, Sequence
from typing import Any

import rclpy
from rclpy._rclpy_pybind11 import InvalidHandle, RCLError

from merlin2_sailor.errors import KnowledgeError
from merlin2_sailor.knowledge.changes import Change, ChangeEvent, ItemKind
from merlin2_sailor.knowledge.model import KnowledgeItem, Proposition
from merlin2_sailor.knowledge.store import DEFAULT_TIMEOUT_SECONDS, KnowledgeBase, Subscriber, Unsubscribe
from merlin2_sailor.ros.background_spinner import BackgroundSpinner
from merlin2_sailor.ros.conversions import knowledge as convert
from merlin2_sailor.ros.knowledge_base_services import APPLY_CHANGES_SERVICE, CHANGES_TOPIC, KIND_SERVICES
from merlin2_sailor.ros.qos import EVENTS
from merlin2_sailor_interfaces import srv
from merlin2_sailor_interfaces.msg import KnowledgeChanges

DEFAULT_NAMESPACE = "/merlin2"
SCHEME = "ros://"


class RemoteKnowledgeBase(KnowledgeBase):
    """A knowledge base served by a knowledge_base node under ``namespace``."""

    def __init__(self, namespace: str = DEFAULT_NAMESPACE, timeout: float = DEFAULT_TIMEOUT_SECONDS) -> None:
        super().__init__()
        self._namespace = "/" + namespace.strip("/") if namespace.strip("/") else ""
        self._timeout = timeout
        self._writer = f"client_{uuid.uuid4().hex}"
        self._kinds = {services.kind: services for services in KIND_SERVICES}
        self._spinner = BackgroundSpinner("knowledge-base-client")
        self._context = self._spinner.context
        self._node = self._spinner.add_node(
            rclpy.create_node(f"knowledge_base_{self._writer}", context=self._context))
        self._clients: dict[str, Any] = {}
        self._clients_lock = threading.Lock()
        self._subscribers: list[Subscriber] = []
        self._subscription: Any = None
        self._closed = False

    @classmethod
    def from_location(cls, location: str, timeout: float = DEFAULT_TIMEOUT_SECONDS) -> RemoteKnowledgeBase:
        """``ros:///namespace`` (``ros:///merlin2``); ``ros://`` alone is the root namespace."""
        return cls(namespace=location.removeprefix(SCHEME) or "/", timeout=timeout)

    # Reads.

    def get(self, kind: ItemKind, key: Hashable) -> KnowledgeItem | None:
        if kind is ItemKind.PROPOSITION:
            predicate, objects, _is_goal = key  # type: ignore[misc]
            candidates = self._get_propositions(predicate, objects[0] if objects else "")
            return next((item for item in candidates if item.key == key), None)
        items = self._get(kind, str(key))
        return items[0] if items else None

    def get_all(self, kind: ItemKind) -> tuple[KnowledgeItem, ...]:
        if kind is ItemKind.PROPOSITION:
            return self._get_propositions("", "")
        return self._get(kind, "")

    def propositions_about(self, object_name: str) -> tuple[Proposition, ...]:
        return self._get_propositions("", object_name)

    # Writes.

    def apply(self, changes: Iterable[Change]) -> tuple[ChangeEvent, ...]:
        request = srv.ApplyChanges.Request(
            changes=[convert.change_to_message(change) for change in changes], writer=self._writer
        )
        response = self._call(srv.ApplyChanges, APPLY_CHANGES_SERVICE, request)
        if not response.success:
            raise KnowledgeError(response.message)
        events = tuple(convert.event_from_message(message) for message in response.events)
        if events:
            self._notify(events)
        return events

    # Events.

    def subscribe(self, subscriber: Subscriber) -> Unsubscribe:
        """Hear every batch: this client's own at once, other writers' from the change topic."""
        with self._clients_lock:
            self._subscribers.append(subscriber)
            if self._subscription is None:
                self._subscription = self._node.create_subscription(
                    KnowledgeChanges, self._name(CHANGES_TOPIC), self._on_changes, EVENTS
                )

        def unsubscribe() -> None:
            with self._clients_lock:
                if subscriber in self._subscribers:
                    self._subscribers.remove(subscriber)

        return unsubscribe

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        self._spinner.close()

    # Internals.

    def _on_changes(self, message: KnowledgeChanges) -> None:
        if message.writer == self._writer or not message.changes:
            return  # this client's own batch, already delivered from the service response
        try:
            events = tuple(convert.event_from_message(change) for change in message.changes)
        except KnowledgeError as error:
            self._node.get_logger().error(f"dropped an unreadable change batch {message.batch}: {error}")
            return
        self._notify(events)

    def _notify(self, events: Sequence[ChangeEvent]) -> None:
        with self._clients_lock:
            subscribers = list(self._subscribers)
        for subscriber in subscribers:
            try:
                subscriber(events)
            except Exception as error:  # one failing subscriber must not starve the others
                self._node.get_logger().error(f"a knowledge subscriber failed: {error!r}")

    def _get(self, kind: ItemKind, name: str) -> tuple[KnowledgeItem, ...]:
        services = self._kinds[kind]
        response = self._call(services.get_type, f"get_{services.plural}",
                              services.get_type.Request(name=name))
        return tuple(services.from_message(message) for message in getattr(response, services.plural))

    def _get_propositions(self, predicate: str, object_name: str) -> tuple[Proposition, ...]:
        request = srv.GetPropositions.Request(predicate=predicate, object_name=object_name)
        response = self._call(srv.GetPropositions, "get_propositions", request)
        return tuple(convert.proposition_from_message(message) for message in response.propositions)

    def _name(self, relative: str) -> str:
        return f"{self._namespace}/{relative}"

    def _call(self, service_type: Any, service: str, request: Any) -> Any:
        if self._closed:
            raise KnowledgeError("this knowledge-base client is closed")
        if not self._context.ok():
            # Ctrl-C shuts every ROS context of the process down, this client's included.
            raise KnowledgeError("the ROS context of this knowledge-base client has shut down")
        try:
            return self._call_service(service_type, service, request)
        except (RCLError, InvalidHandle) as error:  # the context went down during the call
            raise KnowledgeError(f"the knowledge-base client's ROS context failed: {error}") from error

    def _call_service(self, service_type: Any, service: str, request: Any) -> Any:
        name = self._name(service)
        with self._clients_lock:
            client = self._clients.get(name)
            if client is None:
                client = self._clients[name] = self._node.create_client(service_type, name)
        if not client.wait_for_service(timeout_sec=self._timeout):
            raise KnowledgeError(
                f"the knowledge base is not reachable: service {name} did not appear within "
                f"{self._timeout:g} s; is the knowledge_base node running in {self._namespace or '/'}?"
            )
        # One retry: right after a knowledge base restarts, the graph may still list the dead
        # process's service, and a request sent to it is lost. Retrying is safe because saves and
        # deletes are idempotent.
        for _attempt in range(2):
            done = threading.Event()
            future = client.call_async(request)
            future.add_done_callback(lambda _future, finished=done: finished.set())
            if done.wait(self._timeout):
                return future.result()
            client.remove_pending_request(future)
        raise KnowledgeError(f"the knowledge base did not answer {name} within {self._timeout:g} s, twice")
