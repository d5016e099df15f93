"""The one error the state machines raise: a machine or state used against its declaration.

These are programming errors (a wrong transition, an outcome nobody declared), so they are
raised loudly, with the state and machine named, rather than turned into an ``aborted`` outcome
that would hide the bug behind a replan.
"""

from merlin2_sailor.errors import SailorError


class StateMachineError(SailorError):
    """A state or state machine is inconsistent with its own declaration."""
