"""A state machine: states joined by transitions, itself a state so machines nest.

Semantics follow YASMIN 3's Python API: the first state added is the start state unless
:meth:`StateMachine.set_start_state` says otherwise; each state's outcome is looked up in its
transitions and leads to another state, or ends the machine when it names one of the machine's
own outcomes (an outcome that already is a machine outcome needs no transition). Two choices go
further than YASMIN, because MERLIN2's dispatcher relies on them:

* every machine can end with ``canceled``: it is added to the declared outcomes, and
  :meth:`StateMachine.cancel_state` cancels the running state (down through nested machines) and
  ends the machine with ``canceled`` once that state returns, whatever it returned;
* the whole machine is validated before its first run (and on :meth:`StateMachine.validate`), so
  a wrong transition is reported with every problem at once instead of part-way through a
  mission.
"""

import threading
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

from merlin2_sailor_behaviors.state_machines.blackboard import Blackboard
from merlin2_sailor_behaviors.state_machines.errors import StateMachineError
from merlin2_sailor_behaviors.state_machines.outcomes import CANCEL
from merlin2_sailor_behaviors.state_machines.state import State


@dataclass(frozen=True)
class StateEntry:
    """A state as a machine holds it: the state and where each of its outcomes leads."""

    state: State
    transitions: Mapping[str, str] = field(default_factory=dict)


class StateMachine(State):
    """States and transitions run from a start state until an outcome of the machine is reached."""

    def __init__(self, outcomes: Iterable[str]) -> None:
        declared = list(outcomes) if not isinstance(outcomes, str) else outcomes
        if isinstance(declared, list) and declared and CANCEL not in declared:
            declared.append(CANCEL)
        super().__init__(declared)
        self._entries: dict[str, StateEntry] = {}
        self._start_state: str | None = None
        self._current_state: str | None = None
        self._lock = threading.RLock()
        self._validated = False

    # Building.

    def add_state(
        self, name: str, state: State, transitions: Mapping[str, str] | None = None
    ) -> None:
        """Add a state under a unique name; ``transitions`` maps its outcomes to a state name or
        to an outcome of this machine. The first state added becomes the start state."""
        if not isinstance(name, str) or not name:
            raise StateMachineError(f"state names must be non-empty strings, got {name!r}")
        if name in self._entries:
            raise StateMachineError(f"{self} already has a state named {name!r}")
        if name in self.get_outcomes():
            raise StateMachineError(
                f"state name {name!r} is also an outcome of {self}; a transition to it would "
                "be ambiguous, so rename the state"
            )
        if not isinstance(state, State):
            raise StateMachineError(
                f"state {name!r} must be a State (or CbState, StateMachine), got {state!r}"
            )
        if state is self:
            raise StateMachineError(f"{self} cannot contain itself as state {name!r}")
        transitions = dict(transitions or {})
        undeclared = sorted(set(transitions) - set(state.get_outcomes()))
        if undeclared:
            raise StateMachineError(
                f"transitions of state {name!r} use outcome(s) {undeclared} that {state} does "
                f"not declare; it declares {list(state.get_outcomes())}"
            )
        with self._lock:
            self._entries[name] = StateEntry(state, MappingProxyType(transitions))
            if self._start_state is None:
                self._start_state = name
            self._validated = False

    def set_start_state(self, name: str) -> None:
        """Start runs from ``name`` (a state added already, or added before the first run)."""
        with self._lock:
            self._start_state = name
            self._validated = False

    # Inspecting.

    def get_start_state(self) -> str | None:
        """The state runs start from, None while the machine is empty."""
        return self._start_state

    def get_current_state(self) -> str | None:
        """The state running now (this machine's level only), None between runs."""
        with self._lock:
            return self._current_state

    def get_states(self) -> Mapping[str, StateEntry]:
        """Every state by name, read-only."""
        with self._lock:
            return MappingProxyType(dict(self._entries))

    def validate(self) -> None:
        """Check the machine and its nested machines, reporting every problem in one error."""
        with self._lock:
            problems = self._problems()
            if problems:
                raise StateMachineError(f"{self} is not valid:\n- " + "\n- ".join(problems))
            self._validated = True

    def _problems(self) -> list[str]:
        if not self._entries:
            return ["it has no states; add one with add_state before running it"]
        problems = []
        if self._start_state not in self._entries:
            problems.append(
                f"its start state {self._start_state!r} is not one of its states "
                f"{sorted(self._entries)}"
            )
        for name, entry in self._entries.items():
            for outcome, target in entry.transitions.items():
                if target not in self._entries and target not in self.get_outcomes():
                    problems.append(
                        f"state {name!r} goes on {outcome!r} to {target!r}, which is neither a "
                        f"state {sorted(self._entries)} nor an outcome "
                        f"{list(self.get_outcomes())} of the machine"
                    )
            for outcome in entry.state.get_outcomes():
                if outcome not in entry.transitions and outcome not in self.get_outcomes():
                    problems.append(
                        f"outcome {outcome!r} of state {name!r} has no transition and is not "
                        "an outcome of the machine; add a transition for it"
                    )
            if isinstance(entry.state, StateMachine):
                problems += [f"in state {name!r}: {p}" for p in entry.state._problems()]
        return problems

    # Running.

    def execute(self, blackboard: Blackboard) -> str:
        if not self._validated:
            self.validate()
        name = self._start_state
        assert name is not None  # validate() guarantees a start state
        while True:
            entry = self._entries[name]
            with self._lock:
                if self.is_canceled():
                    return CANCEL
                entry.state._begin_run()
                self._current_state = name
            try:
                outcome = entry.state._run(blackboard)
            finally:
                with self._lock:
                    self._current_state = None
            if self.is_canceled():
                return CANCEL
            target = entry.transitions.get(outcome, outcome)
            if target in self.get_outcomes() and target not in self._entries:
                return target
            name = target

    def cancel_state(self) -> None:
        """Cancel the running state (and what it runs) and end this machine with ``canceled``."""
        with self._lock:
            super().cancel_state()
            if self._current_state is not None:
                self._entries[self._current_state].state.cancel_state()

    def __str__(self) -> str:
        return f"StateMachine(states={list(self._entries)}, outcomes={list(self.get_outcomes())})"
