"""BackgroundSpinner: a ROS context of its own, with an executor spinning on a daemon thread.

Code that must make blocking ROS calls from anywhere (the knowledge-base client inside another
node's callback, a test's probe) gets a context of its own, so its calls never wait on, or
deadlock, someone else's executor. Closing it follows the order that keeps the interpreter alive
at exit: executor shut down, context shut down, thread joined, then the nodes destroyed.
"""

from __future__ import annotations

import threading

import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node


class BackgroundSpinner:
    def __init__(self, thread_name: str = "ros-background-spinner") -> None:
        self.context = rclpy.Context()
        # No arguments: the process's own --ros-args (a __node:= remap of the node that owns this
        # spinner) must not rename the private nodes spinning here.
        rclpy.init(args=[], context=self.context)
        self._executor = SingleThreadedExecutor(context=self.context)
        self._nodes: list[Node] = []
        self._thread = threading.Thread(target=self._spin, name=thread_name, daemon=True)
        self._thread.start()

    def add_node(self, node: Node) -> Node:
        """Spin ``node`` (created with ``context=spinner.context``); it is destroyed on close."""
        self._nodes.append(node)
        self._executor.add_node(node)
        return node

    def close(self) -> None:
        self._executor.shutdown()
        rclpy.try_shutdown(context=self.context)
        self._thread.join(timeout=5.0)
        for node in self._nodes:
            node.destroy_node()
        self._nodes.clear()

    def _spin(self) -> None:
        try:
            self._executor.spin()
        except ExternalShutdownException:
            pass
