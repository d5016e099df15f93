"""knowledge_base: a knowledge-base store served over ROS 2, with KANT-shaped services.

Any component reaches the store through these services (or through
:class:`~merlin2_sailor.ros.knowledge_base_client.RemoteKnowledgeBase`, which implements the same
``KnowledgeBase`` port over them), so the store has exactly one writer, as each local store
requires. Every batch that changed something is published on ``knowledge_changes``.

Services (relative names; the node runs under ``/merlin2`` by default, as MERLIN2's KB does):
``get_<kinds>``, ``update_<kind>``, ``delete_all_<kinds>`` for types, objects, predicates,
propositions and actions, plus ``apply_changes`` (a batch in one transaction); their names and
codecs are in :mod:`~merlin2_sailor.ros.knowledge_base_services`. A refused request is answered
with ``success = false`` and the reason; it never stops the node. Symbols are not handed out
here: the anchoring node owns the symbol counter (``anchoring/symbols.py``).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from rclpy.node import Node
from std_msgs.msg import Header

from merlin2_sailor.errors import KnowledgeError, SailorError
from merlin2_sailor.knowledge.changes import Change, ChangeEvent, ItemKind
from merlin2_sailor.knowledge.model import KnowledgeItem
from merlin2_sailor.knowledge.store import KnowledgeBase
from merlin2_sailor.knowledge.stores import open_store
from merlin2_sailor.ros.conversions import knowledge as convert
from merlin2_sailor.ros.knowledge_base_services import (
    APPLY_CHANGES_SERVICE,
    CHANGES_TOPIC,
    KIND_SERVICES,
    KindServices,
)
from merlin2_sailor.ros.node_runner import run_node
from merlin2_sailor.ros.parameters import declare_parameter
from merlin2_sailor.ros.qos import EVENTS
from merlin2_sailor.ros.service_clash import ServiceClash, ServiceClashWatch
from merlin2_sailor_interfaces import srv
from merlin2_sailor_interfaces.msg import KnowledgeChanges

NODE_NAME = "knowledge_base"
#: A refusal is answered with its reason every time, but logged at most this often (a client
#: retrying a bad request in a loop must not flood the log).
WARNING_PERIOD_SECONDS = 5.0


class KnowledgeBaseNode(Node):
    def __init__(self, store: KnowledgeBase | None = None, **node_options: Any) -> None:
        super().__init__(NODE_NAME, **node_options)
        location = declare_parameter(
            self, "store", "memory",
            "Where the knowledge lives: 'memory', 'sqlite:///path/kb.db', 'mongodb://host:port/db' "
            "or 'kant+mongodb://host:port/db' (KANT's DAOs).",
        )
        self._store = store if store is not None else open_store(location)
        self._batch = 0
        self._writer = ""  # writer of the batch being applied, echoed on the change topic
        self._changes_publisher = self.create_publisher(KnowledgeChanges, CHANGES_TOPIC, EVENTS)
        self._unsubscribe = self._store.subscribe(self._publish_changes)
        for services in KIND_SERVICES:
            self._serve_kind(services)
        self.create_service(srv.ApplyChanges, APPLY_CHANGES_SERVICE, self._apply_changes)
        self.exit_code: int | None = None
        self._clash_watch = ServiceClashWatch(self, self._served(), self._on_service_clash)
        counts = ", ".join(f"{len(self._store.get_all(s.kind))} {s.plural}" for s in KIND_SERVICES)
        self.get_logger().info(f"serving the '{location}' store ({counts})")

    def _served(self) -> list[tuple[str, str]]:
        """Our services as (fully qualified name, 'pkg/srv/Type')."""
        return [(name, kinds[0]) for name, kinds in self.get_service_names_and_types_by_node(
            self.get_name(), self.get_namespace()) if kinds]

    def _on_service_clash(self, clash: ServiceClash) -> None:
        """A knowledge base whose service names another serves with other types cannot be reached
        reliably: say so and stop, rather than answer some of the calls meant for the other."""
        self.get_logger().error(
            f"{clash}: another knowledge base (KANT's, in a MERLIN2 deployment) serves this namespace; run this "
            f"node in a namespace of its own (-r __ns:=/sailor, store location ros:///sailor), or use KANT's "
            "(knowledge_base kant+ros:///merlin2). Stopping.")
        self.exit_code = 2

    def destroy_node(self) -> None:
        self._unsubscribe()
        self._store.close()
        super().destroy_node()

    # Publishing.

    def _publish_changes(self, events: Sequence[ChangeEvent]) -> None:
        """Called by the store inside each batch that changed something, in batch order."""
        self._batch += 1
        self._changes_publisher.publish(KnowledgeChanges(
            header=Header(stamp=self.get_clock().now().to_msg()),
            batch=self._batch,
            writer=self._writer,
            changes=[convert.event_to_message(event) for event in events],
        ))

    # Services.

    def _serve_kind(self, services: KindServices) -> None:
        singular = services.kind.value
        self.create_service(services.get_type, f"get_{services.plural}",
                            lambda request, response: self._get(services, request, response))
        self.create_service(services.update_type, f"update_{singular}",
                            lambda request, response: self._update(services, request, response))
        self.create_service(services.delete_all_type, f"delete_all_{services.plural}",
                            lambda request, response: self._delete_all(services, request, response))

    def _get(self, services: KindServices, request: Any, response: Any) -> Any:
        items: Sequence[KnowledgeItem]
        if services.kind is ItemKind.PROPOSITION:
            items = (self._store.propositions_about(request.object_name) if request.object_name
                     else self._store.get_all(services.kind))
            if request.predicate:
                items = [item for item in items if item.predicate == request.predicate]  # type: ignore[union-attr]
        elif request.name:
            found = self._store.get(services.kind, request.name)
            items = [found] if found is not None else []
        else:
            items = self._store.get_all(services.kind)
        setattr(response, services.plural, [services.to_message(item) for item in items])
        return response

    def _update(self, services: KindServices, request: Any, response: Any) -> Any:
        def change() -> list[Change]:
            item = services.from_message(getattr(request, services.kind.value))
            if request.operation == request.OPERATION_SAVE:
                return [Change.save(item)]
            if request.operation == request.OPERATION_DELETE:
                return [Change.delete(item)]
            raise KnowledgeError(f"unknown operation {request.operation}; use OPERATION_SAVE or OPERATION_DELETE")

        return self._write(change, response)

    def _delete_all(self, services: KindServices, _request: Any, response: Any) -> Any:
        return self._write(lambda: [Change.delete(item) for item in self._store.get_all(services.kind)], response)

    def _apply_changes(self, request: srv.ApplyChanges.Request,
                       response: srv.ApplyChanges.Response) -> srv.ApplyChanges.Response:
        batch_before = self._batch
        self._writer = request.writer
        try:
            response = self._write(lambda: [convert.change_from_message(m) for m in request.changes],
                                   response, keep_events=True)
        finally:
            self._writer = ""
        response.batch = self._batch if self._batch != batch_before else 0
        return response

    def _write(self, make_changes: Callable[[], list[Change]], response: Any,
               keep_events: bool = False) -> Any:
        """Apply a batch; a refused batch is reported in the response and logged, never raised."""
        try:
            events = self._store.apply(make_changes())
        except SailorError as error:
            response.success, response.message = False, str(error)
            self.get_logger().warning(f"write refused: {error}", throttle_duration_sec=WARNING_PERIOD_SECONDS)
            return response
        except Exception as error:  # a database failure must not take the node down
            response.success, response.message = False, f"the store failed: {error}"
            self.get_logger().error(f"the store failed to apply a batch: {error!r}",
                                    throttle_duration_sec=WARNING_PERIOD_SECONDS)
            return response
        response.success = True
        if keep_events:
            response.events = [convert.event_to_message(event) for event in events]
        return response


def main(argv: Sequence[str] | None = None) -> int:
    return run_node(KnowledgeBaseNode, argv)


if __name__ == "__main__":
    raise SystemExit(main())
