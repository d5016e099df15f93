"""Choose between the real ``yasmin`` package and the local implementation of its API.

YASMIN is not on PyPI, so the project carries :mod:`.state`, :mod:`.state_machine` and
:mod:`.blackboard`, which follow YASMIN 3's Python API. Where YASMIN is installed (a MERLIN2
workspace), behaviours should be real YASMIN states so MERLIN2's tools (the viewer, its FSM
actions) see them; :func:`load_state_machine_api` returns whichever is available and says which.

Only a missing ``yasmin`` module selects the local implementation: any other error raised while
importing YASMIN (a broken install) propagates, rather than silently running different code.
The outcomes come from ``yasmin_ros.basic_outcomes`` when it is importable; they are the same
strings either way.

Set ``SAILOR_STATE_MACHINES=local`` to use the local implementation even where YASMIN is
installed (for example to run this project's tests in a MERLIN2 workspace).
"""

import importlib
import os
from dataclasses import dataclass
from typing import Any

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor_behaviors.state_machines import outcomes as local_outcomes
from merlin2_sailor_behaviors.state_machines.blackboard import Blackboard
from merlin2_sailor_behaviors.state_machines.state import CbState, State
from merlin2_sailor_behaviors.state_machines.state_machine import StateMachine

REAL_PACKAGE = "yasmin"
REAL_OUTCOMES_MODULE = "yasmin_ros.basic_outcomes"
SELECTION_VARIABLE = "SAILOR_STATE_MACHINES"
"""Environment variable: ``auto`` (default: real YASMIN when importable), ``local`` or ``real``."""


@dataclass(frozen=True)
class StateMachineApi:
    """The classes and outcomes behaviours are written against, from one implementation."""

    State: type
    CbState: type
    StateMachine: type
    Blackboard: type
    SUCCEED: str
    ABORT: str
    CANCEL: str
    source: str
    """``"yasmin"`` for the real package, ``"local"`` for this project's implementation."""


def local_api() -> StateMachineApi:
    """This project's implementation of the API, whatever is installed."""
    return StateMachineApi(
        State=State,
        CbState=CbState,
        StateMachine=StateMachine,
        Blackboard=Blackboard,
        SUCCEED=local_outcomes.SUCCEED,
        ABORT=local_outcomes.ABORT,
        CANCEL=local_outcomes.CANCEL,
        source="local",
    )


def use_real_yasmin() -> bool:
    """Whether the real ``yasmin`` package can be imported here."""
    return _import_optional(REAL_PACKAGE) is not None


def load_state_machine_api(selection: str | None = None) -> StateMachineApi:
    """The API to write behaviours against: ``selection`` (or ``$SAILOR_STATE_MACHINES``) is
    ``auto`` (real YASMIN when importable, else local), ``local`` or ``real``.

    Raises:
        ConfigurationError: an unknown selection, or ``real`` where YASMIN is not installed.
    """
    selection = (selection or os.environ.get(SELECTION_VARIABLE) or "auto").lower()
    if selection not in ("auto", "local", "real"):
        raise ConfigurationError(
            f"{SELECTION_VARIABLE}={selection!r} is not a choice; use auto, local or real"
        )
    if selection == "local":
        return local_api()
    yasmin = _import_optional(REAL_PACKAGE)
    if yasmin is None:
        if selection == "real":
            raise ConfigurationError(
                "the real yasmin package was requested but cannot be imported; source a "
                f"workspace that builds YASMIN, or set {SELECTION_VARIABLE}=auto"
            )
        return local_api()
    real_outcomes = _import_optional(REAL_OUTCOMES_MODULE)
    return StateMachineApi(
        State=yasmin.State,
        CbState=yasmin.CbState,
        StateMachine=yasmin.StateMachine,
        Blackboard=yasmin.Blackboard,
        SUCCEED=getattr(real_outcomes, "SUCCEED", local_outcomes.SUCCEED),
        ABORT=getattr(real_outcomes, "ABORT", local_outcomes.ABORT),
        CANCEL=getattr(real_outcomes, "CANCEL", local_outcomes.CANCEL),
        source="yasmin",
    )


def _import_optional(module_name: str) -> Any:
    """The module, or None when it (or a package it lives in) is not installed at all."""
    try:
        return importlib.import_module(module_name)
    except ModuleNotFoundError as error:
        missing = error.name or ""
        if module_name == missing or module_name.startswith(missing + "."):
            return None
        raise
