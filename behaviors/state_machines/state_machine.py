"""A state machine: states joined by transitions, itself a state so machines nest.

Semantics are YASMIN 3.2's Python ones, so a behaviour runs the same here and on the real package
(the behaviour suite runs on both where YASMIN is installed):

* the first state added is the start state unless :meth:`StateMachine.set_start_state` says
  otherwise; each state's outcome is looked up in its transitions and leads to another state, or
  ends the machine when it names one of the machine's own outcomes;
* a machine has exactly the outcomes it declares: one that can be cancelled declares ``canceled``
  and its states return it when cancelled. :meth:`StateMachine.cancel_state` cancels the running
  state (down through nested machines) and stops the machine before its next state; a machine
  stopped that way between two states raises RuntimeError, as YASMIN's does;
* errors are YASMIN's built-in types (KeyError, ValueError, RuntimeError), through
  :mod:`.errors`, so ``except StateMachineError`` also catches them all;
* remappings per state and start / transition / end callbacks, with YASMIN's signatures.

Beyond YASMIN, and compatible with it: validation reports every problem of a machine in one
error, and the current state is cleared however a run ends.
"""

import logging
import threading
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

from merlin2_sailor_behaviors.state_machines.blackboard import Blackboard
from merlin2_sailor_behaviors.state_machines.errors import (
    StateMachineKeyError,
    StateMachineRuntimeError,
    StateMachineValueError,
)
from merlin2_sailor_behaviors.state_machines.state import State

_logger = logging.getLogger(__name__)

Callback = tuple[Callable[..., None], Sequence[Any]]


@dataclass(frozen=True)
class StateEntry:
    """A state as a machine holds it: the state, where each of its outcomes leads, its remappings."""

    state: State
    transitions: Mapping[str, str] = field(default_factory=dict)
    remappings: Mapping[str, str] = field(default_factory=dict)


class StateMachine(State):
    """States and transitions run from a start state until an outcome of the machine is reached."""

    def __init__(self, outcomes: Iterable[str]) -> None:
        super().__init__(outcomes)
        self._entries: dict[str, StateEntry] = {}
        self._start_state: str | None = None
        self._current_state: str | None = None
        self._lock = threading.RLock()
        self._validated = False
        self._start_callbacks: list[Callback] = []
        self._transition_callbacks: list[Callback] = []
        self._end_callbacks: list[Callback] = []

    # Building.

    def add_state(
        self,
        name: str,
        state: State,
        transitions: Mapping[str, str] | None = None,
        remappings: Mapping[str, str] | None = None,
    ) -> None:
        """Add a state under a unique name; ``transitions`` maps its outcomes to a state name or
        to an outcome of this machine; ``remappings`` maps the keys it uses to the blackboard's.
        The first state added becomes the start state."""
        if not isinstance(name, str) or not name:
            raise StateMachineValueError(f"state names must be non-empty strings, got {name!r}")
        if name in self._entries:
            raise StateMachineKeyError(f"{self} already has a state named {name!r}")
        if name in self.get_outcomes():
            raise StateMachineKeyError(
                f"state name {name!r} is also an outcome of {self}; a transition to it would "
                "be ambiguous, so rename the state"
            )
        if not isinstance(state, State):
            raise StateMachineValueError(f"state {name!r} must be a State (or CbState, StateMachine), got {state!r}")
        if state is self:
            raise StateMachineValueError(f"{self} cannot contain itself as state {name!r}")
        transitions = dict(transitions or {})
        empty = [f"{source!r} -> {target!r}" for source, target in transitions.items() if not source or not target]
        if empty:
            raise StateMachineValueError(f"transitions of state {name!r} have an empty source or target: {empty}")
        undeclared = sorted(set(transitions) - set(state.get_outcomes()))
        if undeclared:
            raise StateMachineKeyError(
                f"transitions of state {name!r} use outcome(s) {undeclared} that {state} does "
                f"not declare; it declares {list(state.get_outcomes())}"
            )
        with self._lock:
            self._entries[name] = StateEntry(
                state, MappingProxyType(transitions), MappingProxyType(dict(remappings or {}))
            )
            if self._start_state is None:
                self._start_state = name
            self._validated = False

    def set_start_state(self, name: str) -> None:
        """Start runs from ``name``, a state added already."""
        if not name:
            raise StateMachineValueError("the start state's name cannot be empty")
        with self._lock:
            if name not in self._entries:
                raise StateMachineKeyError(
                    f"start state {name!r} is not a state of {self}; add it first (states: {sorted(self._entries)})"
                )
            self._start_state = name
            self._validated = False

    def add_start_cb(self, cb: Callable[..., None], args: Sequence[Any] | None = None) -> None:
        """Call ``cb(blackboard, start_state, *args)`` when a run starts."""
        self._start_callbacks.append((cb, tuple(args or ())))

    def add_transition_cb(self, cb: Callable[..., None], args: Sequence[Any] | None = None) -> None:
        """Call ``cb(blackboard, from_state, to_state, outcome, *args)`` on every transition."""
        self._transition_callbacks.append((cb, tuple(args or ())))

    def add_end_cb(self, cb: Callable[..., None], args: Sequence[Any] | None = None) -> None:
        """Call ``cb(blackboard, outcome, *args)`` when a run ends with an outcome."""
        self._end_callbacks.append((cb, tuple(args or ())))

    # Inspecting.

    def get_start_state(self) -> str | None:
        """The state runs start from, None while the machine is empty."""
        return self._start_state

    def get_current_state(self) -> str:
        """The state running now (this machine's level only), ``""`` between runs."""
        with self._lock:
            return self._current_state or ""

    def get_states(self) -> Mapping[str, StateEntry]:
        """Every state by name, read-only."""
        with self._lock:
            return MappingProxyType(dict(self._entries))

    def validate(self, strict_mode: bool = False) -> None:
        """Check the machine and its nested machines, reporting every problem in one error.

        As in YASMIN: every transition must lead to a state or an outcome of the machine; in
        ``strict_mode``, also every outcome of every state must be handled and every outcome of the
        machine reachable.

        Raises:
            StateMachineRuntimeError: the machine has no start state (no states).
            StateMachineKeyError: the problems found.
        """
        with self._lock:
            if self._start_state is None:
                raise StateMachineRuntimeError(f"{self} has no start state; add a state with add_state first")
            problems = self._problems(strict_mode)
            if problems:
                raise StateMachineKeyError(f"{self} is not valid:\n- " + "\n- ".join(problems))
            self._validated = True

    def _problems(self, strict_mode: bool) -> list[str]:
        problems = []
        reached: set[str] = set()
        for name, entry in self._entries.items():
            for outcome, target in entry.transitions.items():
                reached.add(target)
                if target not in self._entries and target not in self.get_outcomes():
                    problems.append(
                        f"state {name!r} goes on {outcome!r} to {target!r}, which is neither a "
                        f"state {sorted(self._entries)} nor an outcome "
                        f"{list(self.get_outcomes())} of the machine"
                    )
            if strict_mode:
                for outcome in entry.state.get_outcomes():
                    if outcome in entry.transitions:
                        continue
                    if outcome in self.get_outcomes():
                        reached.add(outcome)
                    else:
                        problems.append(
                            f"outcome {outcome!r} of state {name!r} has no transition and is not "
                            "an outcome of the machine; add a transition for it"
                        )
            if isinstance(entry.state, StateMachine):
                if entry.state._start_state is None:
                    problems.append(f"in state {name!r}: it has no states")
                else:
                    problems += [f"in state {name!r}: {p}" for p in entry.state._problems(strict_mode)]
        if strict_mode:
            problems += [
                f"outcome {outcome!r} of the machine is never reached" for outcome in self.get_outcomes()
                if outcome not in reached
            ]
        return problems

    # Running.

    def execute(self, blackboard: Blackboard) -> str:
        self.validate()
        name = self._start_state
        self._call(self._start_callbacks, blackboard, name)
        with self._lock:
            self._current_state = name
        try:
            while True:
                entry = self._entries[name]
                with self._lock:
                    # Checked and started under the lock that cancel_state takes, so a cancel that
                    # arrives now reaches the state instead of being forgotten as it starts.
                    if self.is_canceled():
                        break
                    entry.state._begin_run()
                blackboard.remappings = entry.remappings
                outcome = entry.state._run(blackboard)
                if outcome not in entry.state.get_outcomes():
                    raise StateMachineKeyError(f"outcome {outcome!r} is not declared by state {name!r}")
                target = entry.transitions.get(outcome, outcome)
                if target in self.get_outcomes():
                    self._call(self._end_callbacks, blackboard, target)
                    return target
                if target not in self._entries:
                    raise StateMachineKeyError(
                        f"outcome {outcome!r} of state {name!r} leads to {target!r}, which is neither a state nor "
                        f"an outcome of {self}"
                    )
                self._call(self._transition_callbacks, blackboard, name, target, outcome)
                with self._lock:
                    self._current_state = name = target
            raise StateMachineRuntimeError(
                f"{self} was cancelled between two states ({name!r} was next): it ends without an outcome"
            )
        finally:
            blackboard.remappings = {}
            with self._lock:
                self._current_state = None

    def cancel_state(self) -> None:
        """Cancel the running state (and what it runs); the machine runs no further state."""
        with self._lock:
            super().cancel_state()
            if self._current_state is not None:
                self._entries[self._current_state].state.cancel_state()

    @staticmethod
    def _call(callbacks: list[Callback], blackboard: Blackboard, *arguments: Any) -> None:
        """YASMIN logs a failing callback and goes on; so does this."""
        for callback, extra in callbacks:
            try:
                callback(blackboard, *arguments, *extra)
            except Exception:
                _logger.exception("state-machine callback %r failed; continuing", callback)

    def __str__(self) -> str:
        return f"StateMachine(states={list(self._entries)}, outcomes={list(self.get_outcomes())})"
