"""YASMIN 3's Python state-machine API, from the real package when installed, else local.

Behaviours import the names below and run unchanged on either implementation::

    from merlin2_sailor_behaviors.state_machines import SUCCEED, CbState, StateMachine

The choice is made once, when this package is first imported (see :mod:`.loader`, and its
``SAILOR_STATE_MACHINES`` variable). Tests of the local implementation import its modules
(:mod:`.state`, :mod:`.state_machine`, :mod:`.blackboard`) directly, so they test it even where
YASMIN is installed.
"""

from merlin2_sailor_behaviors.state_machines.errors import StateMachineError
from merlin2_sailor_behaviors.state_machines.loader import (
    StateMachineApi,
    load_state_machine_api,
    local_api,
    use_real_yasmin,
)
from merlin2_sailor_behaviors.state_machines.outcomes import BASIC_OUTCOMES

_API = load_state_machine_api()

State = _API.State
CbState = _API.CbState
StateMachine = _API.StateMachine
Blackboard = _API.Blackboard
SUCCEED = _API.SUCCEED
ABORT = _API.ABORT
CANCEL = _API.CANCEL
IMPLEMENTATION = _API.source
"""``"yasmin"`` or ``"local"``: which implementation the names above come from."""

__all__ = [
    "ABORT",
    "BASIC_OUTCOMES",
    "CANCEL",
    "IMPLEMENTATION",
    "SUCCEED",
    "Blackboard",
    "CbState",
    "State",
    "StateMachine",
    "StateMachineApi",
    "StateMachineError",
    "load_state_machine_api",
    "local_api",
    "use_real_yasmin",
]
