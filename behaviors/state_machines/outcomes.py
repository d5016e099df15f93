"""The three outcomes every MERLIN2 action ends with, spelled as YASMIN spells them.

Kept in one module so behaviours, the local state machines and the dispatcher compare against the
same strings, and so switching to the real ``yasmin`` package changes no outcome a caller sees.
"""

SUCCEED = "succeeded"
"""The state did what it was asked to."""

ABORT = "aborted"
"""The state tried and failed; a dispatcher may replan."""

CANCEL = "canceled"
"""Someone asked the state to stop (see ``State.cancel_state``) and it did."""

BASIC_OUTCOMES = (SUCCEED, ABORT, CANCEL)
"""What a MERLIN2 action's state machine may end with."""
