"""The errors the state machines raise: a machine or state used against its declaration.

These are programming errors (a wrong transition, an outcome nobody declared), so they are
raised loudly, with the state and machine named, rather than turned into an ``aborted`` outcome
that would hide the bug behind a replan. Each is also the built-in exception YASMIN 3.2 raises in
the same case (KeyError, ValueError or RuntimeError), so code that handles YASMIN's errors handles
these, and ``except StateMachineError`` catches them all.
"""

from merlin2_sailor.errors import SailorError


class StateMachineError(SailorError):
    """A state or state machine is inconsistent with its own declaration."""


class StateMachineKeyError(StateMachineError, KeyError):
    """An unknown or repeated name: a state, an outcome, a transition (YASMIN: KeyError)."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""  # KeyError would quote the message


class StateMachineValueError(StateMachineError, ValueError):
    """A malformed declaration, or an outcome a state did not declare (YASMIN: ValueError)."""


class StateMachineRuntimeError(StateMachineError, RuntimeError):
    """A machine that cannot run: no start state, or a cancel between two states (YASMIN: RuntimeError)."""
