"""Run a node until Ctrl-C, SIGTERM or an external shutdown, and always clean up.

Every entry point goes through :func:`run_node`, so all nodes shut down the same way: the
executor is shut down, the node destroyed and the context shut down, and the process exits 0
after a requested stop. A node that leaves an executor thread spinning at exit aborts the
interpreter, so nothing is left to chance here.

Signals are handled here, in Python, not by rclpy's own handler. rclpy's handler runs
asynchronously and triggers the guard conditions of every executor; a SIGINT that arrived while
the node was already shutting down made it trigger invalidated ones and crash the process with a
segmentation fault (seen under load in the test suite). Here a signal only sets a flag, and the
node spins in short slices so the flag is seen within a tenth of a second.
"""

from __future__ import annotations

import signal
import sys
import threading
from collections.abc import Callable, Sequence

import rclpy
from rclpy._rclpy_pybind11 import RCLError
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions

from merlin2_sailor.errors import SailorError

SPIN_SLICE_SECONDS = 0.1


def run_node(
    make_node: Callable[[], Node],
    argv: Sequence[str] | None = None,
    threads: int = 1,
) -> int:
    """Create the node with ``make_node`` and spin it; return the process exit code.

    ``threads`` > 1 uses a multi-threaded executor, for nodes whose service callbacks must not
    wait behind long subscription callbacks. A SailorError while building the node (a bad
    parameter, a missing model file) is logged as one line and exits with code 2.

    A node with a job that ends (a mission) sets an ``exit_code`` attribute when it is done:
    the spin stops and the process exits with that code.
    """
    arguments = list(argv) if argv is not None else sys.argv
    try:
        rclpy.init(args=arguments, signal_handler_options=SignalHandlerOptions.NO)
    except RCLError as error:  # a malformed --ros-args: say so in one line, not a traceback
        print(f"cannot start: invalid ROS arguments {arguments[1:]}: {error}", file=sys.stderr, flush=True)
        return 2
    stop_requested = threading.Event()
    # Ctrl-C, and SIGTERM (the launcher's second step, systemd, docker stop), end the spin loop.
    for signal_number in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signal_number, lambda *_: stop_requested.set())
    node: Node | None = None
    executor = MultiThreadedExecutor(num_threads=threads) if threads > 1 else SingleThreadedExecutor()
    try:
        node = make_node()
        executor.add_node(node)
        while not stop_requested.is_set() and rclpy.ok():
            executor.spin_once(timeout_sec=SPIN_SLICE_SECONDS)
            exit_code = getattr(node, "exit_code", None)
            if exit_code is not None:
                return int(exit_code)
    except ExternalShutdownException:
        pass
    except SailorError as error:
        name = node.get_name() if node is not None else "node"
        print(f"[{name}] cannot start: {error}", file=sys.stderr, flush=True)
        return 2
    finally:
        executor.shutdown()
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0
