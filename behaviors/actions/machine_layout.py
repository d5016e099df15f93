"""A machine's states as the YASMIN viewer draws them: a flat list with parent ids and current states.

The viewer (``yasmin_viewer``) reads ``yasmin_msgs/StateMachine`` messages on ``/fsm_viewer``: every
state of every level in one list, each with its parent's id, its transitions and outcomes, and, for
a nested machine, the id of the child running now. :func:`machine_layout` computes that list from a
running machine, local or real YASMIN (their ``get_states()`` entries differ in shape only), so the
ROS layer only copies it into messages.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from merlin2_sailor_behaviors.actions.progress import MAX_DEPTH

NO_STATE = -1
"""The viewer's id for "none": the root's parent, a machine between runs."""


@dataclass
class StateLayout:
    """One state, as one ``yasmin_msgs/State``."""

    id: int
    parent: int
    name: str
    transitions: dict[str, str]
    outcomes: list[str]
    is_fsm: bool
    current_state: int = NO_STATE
    children: list[int] = field(default_factory=list)


def _entry_parts(entry: Any) -> tuple[Any, Mapping[str, str]]:
    """(state, transitions) of a ``get_states()`` entry: an object (local) or a dict (YASMIN)."""
    if isinstance(entry, Mapping):
        return entry.get("state"), entry.get("transitions") or {}
    return getattr(entry, "state", None), getattr(entry, "transitions", {}) or {}


def _is_machine(state: Any) -> bool:
    return callable(getattr(state, "get_states", None)) and callable(getattr(state, "get_current_state", None))


def machine_layout(name: str, machine: Any) -> list[StateLayout]:
    """Every state of ``machine`` (named ``name`` at the root), parents before children."""
    layouts: list[StateLayout] = []

    def add(state_name: str, state: Any, transitions: Mapping[str, str], parent: int, depth: int) -> None:
        layout = StateLayout(
            id=len(layouts), parent=parent, name=state_name, transitions=dict(transitions),
            outcomes=sorted(state.get_outcomes()), is_fsm=_is_machine(state),
        )
        layouts.append(layout)
        if not layout.is_fsm or depth >= MAX_DEPTH:
            return
        current = state.get_current_state()
        for child_name, entry in state.get_states().items():
            child_state, child_transitions = _entry_parts(entry)
            if child_state is None:
                continue
            child_id = len(layouts)
            layout.children.append(child_id)
            if child_name == current:
                layout.current_state = child_id
            add(child_name, child_state, child_transitions, layout.id, depth + 1)

    add(name, machine, {}, NO_STATE, 0)
    return layouts
