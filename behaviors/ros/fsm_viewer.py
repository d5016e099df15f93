"""SAILOR's running state machines in the YASMIN viewer, where YASMIN's messages are installed.

The viewer (``ros2 run yasmin_viewer yasmin_viewer_node``) draws every ``yasmin_msgs/StateMachine``
published on ``/fsm_viewer``. The behaviours node publishes the machine of each running goal there,
a few times a second, laid out by :func:`~merlin2_sailor_behaviors.actions.machine_layout.machine_layout`,
whether the machine is YASMIN's or the project's own. Where ``yasmin_msgs`` is not importable the
publisher does nothing: the viewer cannot run there either.
"""

from __future__ import annotations

import importlib
from typing import Any

from rclpy.node import Node

from merlin2_sailor_behaviors.actions.machine_layout import machine_layout

VIEWER_TOPIC = "/fsm_viewer"
"""Where YASMIN's viewer listens (yasmin_viewer's YasminViewerPub publishes there)."""
VIEWER_PERIOD = 0.25
"""Seconds between two publications of a running machine: the viewer's own default rate, 4 Hz."""
QUEUE_DEPTH = 10


class FsmViewerPublisher:
    """Publishes machines as ``yasmin_msgs/StateMachine``; ``enabled`` is False without yasmin_msgs."""

    def __init__(self, node: Node) -> None:
        try:
            self._messages: Any = importlib.import_module("yasmin_msgs.msg")
        except ImportError:
            self._messages = None
            self._publisher = None
            return
        self._publisher = node.create_publisher(self._messages.StateMachine, VIEWER_TOPIC, QUEUE_DEPTH)

    @property
    def enabled(self) -> bool:
        return self._publisher is not None

    def publish(self, name: str, machine: Any) -> None:
        """Publish ``machine``'s layout with ``name`` as its root (the viewer lists machines by it)."""
        if self._publisher is None:
            return
        messages = self._messages
        states = []
        for layout in machine_layout(name, machine):
            transitions = [messages.Transition(outcome=outcome, state=target)
                           for outcome, target in layout.transitions.items()]
            states.append(messages.State(
                id=layout.id, parent=layout.parent, name=layout.name, transitions=transitions,
                outcomes=layout.outcomes, is_fsm=layout.is_fsm, current_state=layout.current_state,
            ))
        self._publisher.publish(messages.StateMachine(states=states))
