"""Blocking service calls for the behaviours' clients: bounded, cancellable, with clear errors."""

from __future__ import annotations

import threading
from typing import Any

from rclpy.callback_groups import CallbackGroup
from rclpy.node import Node

from merlin2_sailor_behaviors.actions.errors import BehaviorError
from merlin2_sailor_behaviors.ros.waiting import WaitEnd, wait_for, wait_for_future


class ServiceCaller:
    """Calls services of one node from worker threads; the node is spun by its executor."""

    def __init__(
        self, node: Node, timeout: float, stopping: threading.Event, callback_group: CallbackGroup | None = None
    ) -> None:
        self._node = node
        self._timeout = timeout
        self._stopping = stopping
        self._group = callback_group
        self._clients: dict[str, Any] = {}
        self._lock = threading.Lock()

    def call(self, service_type: Any, name: str, request: Any, provider: str) -> Any:
        """The response of service ``name``; ``provider`` names who serves it, for the message.

        Raises:
            BehaviorError: the service did not appear or answer within the timeout, or the node
                is shutting down.
        """
        with self._lock:
            client = self._clients.get(name)
            if client is None:
                # rclpy's own method: subclasses may narrow it (simple_node's, under every MERLIN2
                # node, takes no callback group).
                client = self._clients[name] = Node.create_client(
                    self._node, service_type, name, callback_group=self._group)
        end = wait_for(client.service_is_ready, self._timeout, self._stopping)
        if end is WaitEnd.STOPPING:
            raise BehaviorError("the behaviors node is shutting down")
        if end is not WaitEnd.DONE:
            raise BehaviorError(
                f"service {client.srv_name} is not available after {self._timeout:g} s; is {provider} running?"
            )
        future = client.call_async(request)
        end = wait_for_future(future, self._timeout, self._stopping)
        if end is not WaitEnd.DONE:
            client.remove_pending_request(future)
            if end is WaitEnd.STOPPING:
                raise BehaviorError("the behaviors node is shutting down")
            raise BehaviorError(f"service {client.srv_name} did not answer within {self._timeout:g} s")
        response = future.result()
        if response is None:
            raise BehaviorError(f"service {client.srv_name} failed: {future.exception()!r}")
        return response
