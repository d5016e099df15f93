"""Ending MERLIN2's nodes cleanly: simple_node spins each node on threads of its own.

simple_node's spin and wake threads run until ROS's context dies, and say so by raising "context
is not valid" (an RCLError); daemon threads cut off by the interpreter's exit print a stray
"Exception in thread". Whoever runs MERLIN2 nodes (the actions, the mission) shuts ROS down
inside :func:`ros_shutdown_ends_node_threads`, then gives the threads their moment with
:func:`let_node_threads_end`.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Iterator, Sequence

THREAD_END_SECONDS = 2.0
"""How long each of MERLIN2's node threads may take to end once ROS has shut down."""


@contextlib.contextmanager
def ros_shutdown_ends_node_threads() -> Iterator[None]:
    """While ROS shuts down, a node thread that ends with ROS's "context is not valid" has ended as
    it should (simple_node's executor threads spin until the context dies, and say so with an
    RCLError); any other exception in a thread is reported as usual."""
    from rclpy._rclpy_pybind11 import InvalidHandle, RCLError
    from rclpy.executors import ExternalShutdownException

    report = threading.excepthook

    def hook(arguments: threading.ExceptHookArgs) -> None:
        if not issubclass(arguments.exc_type, (RCLError, InvalidHandle, ExternalShutdownException)):
            report(arguments)

    threading.excepthook = hook
    try:
        yield
    finally:
        threading.excepthook = report


def let_node_threads_end(nodes: Sequence, timeout: float = THREAD_END_SECONDS) -> None:
    """Give simple_node's spin and wake threads the moment they need to see ROS shut down: daemon
    threads cut off by the interpreter's exit print a stray "Exception in thread"."""
    for node in nodes:
        for attribute in ("_spin_thread", "_wake_thread"):  # simple_node's, where it is used
            thread = getattr(node, attribute, None)
            if isinstance(thread, threading.Thread) and thread is not threading.current_thread():
                thread.join(timeout)
