"""The blackboard keys behaviours share with whoever runs them.

Each PDDL parameter is a key of its own, holding its object's name (``blackboard["destination"]
== "kitchen"``), as the dispatcher writes them; :data:`PLAN_STEP_KEY` holds the whole step. The
keys below are the rest of the contract; :data:`REASON_KEY` (why a behaviour did not succeed, in
words, written by the state that aborted) is read by the dispatcher too.
"""

from merlin2_sailor_behaviors.planning.dispatcher import PLAN_STEP_KEY, REASON_KEY

WARNINGS_KEY = "warnings"
"""Things that went wrong without stopping the behaviour (a list of sentences)."""

CLASS_NAME_KEY = "class_name"
"""find_object outside PDDL: the detector class to look for when no symbol is given."""

FOUND_SYMBOL_KEY = "found_symbol"
"""find_object: the symbol of the anchor it reacquired."""

FOUND_AT_KEY = "found_at"
"""find_object: the waypoint where it reacquired it (the robot stays there)."""

__all__ = [
    "CLASS_NAME_KEY",
    "FOUND_AT_KEY",
    "FOUND_SYMBOL_KEY",
    "PLAN_STEP_KEY",
    "REASON_KEY",
    "WARNINGS_KEY",
]
