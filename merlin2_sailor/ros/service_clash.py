"""Another node serving one of our service names with another type: a deployment mistake to say.

Two servers of one service name with different types both register, and each client then talks to
whichever DDS matches: calls fail or hang with nothing in the logs to say why. It happens when
SAILOR's knowledge_base node is started in MERLIN2's ``/merlin2``, where KANT's node serves
``get_types``, ``update_type``... with kant_msgs types. :class:`ServiceClashWatch` looks at the
graph now and then (discovery is asynchronous, and the other node may start later) and reports
each clash once, naming the service, the other type and the nodes that serve it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass

from rclpy.node import Node


@dataclass(frozen=True)
class ServiceClash:
    """A service name of ours that another node serves with another type."""

    service: str
    our_type: str
    other_types: tuple[str, ...]
    other_nodes: tuple[str, ...]

    def __str__(self) -> str:
        nodes = ", ".join(self.other_nodes) or "another node"
        return f"{self.service} is also served by {nodes} as {' / '.join(self.other_types)} (ours: {self.our_type})"


def service_clashes(node: Node, our_services: Iterable[tuple[str, str]]) -> list[ServiceClash]:
    """Clashes with ``our_services`` ((fully qualified name, 'pkg/srv/Type')) in the graph now."""
    ours = dict(our_services)
    clashes = []
    for name, types in node.get_service_names_and_types():
        if name in ours and any(kind != ours[name] for kind in types):
            others = tuple(kind for kind in types if kind != ours[name])
            clashes.append(ServiceClash(name, ours[name], others, _servers_of(node, name, others)))
    return clashes


def _servers_of(node: Node, service: str, types: tuple[str, ...]) -> tuple[str, ...]:
    servers = []
    for name, namespace in node.get_node_names_and_namespaces():
        try:
            served = node.get_service_names_and_types_by_node(name, namespace)
        except Exception:  # noqa: BLE001 - a node that left the graph meanwhile
            continue
        if any(item_name == service and set(item_types) & set(types) for item_name, item_types in served):
            servers.append(f"{namespace.rstrip('/')}/{name}")
    return tuple(servers)


class ServiceClashWatch:
    """Check the graph every ``period`` seconds; ``on_clash`` gets each new clash once."""

    def __init__(self, node: Node, our_services: Iterable[tuple[str, str]], on_clash: Callable[[ServiceClash], None],
                 period: float = 2.0) -> None:
        self._node = node
        self._ours = tuple(our_services)
        self._on_clash = on_clash
        self._reported: set[tuple[str, tuple[str, ...]]] = set()
        node.create_timer(period, self.check)

    def check(self) -> list[ServiceClash]:
        new = []
        for clash in service_clashes(self._node, self._ours):
            key = (clash.service, clash.other_types)
            if key not in self._reported:
                self._reported.add(key)
                new.append(clash)
                self._on_clash(clash)
        return new
