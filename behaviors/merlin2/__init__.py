"""SAILOR's behaviours as MERLIN2 actions, where MERLIN2 is installed.

MERLIN2 (https://github.com/MERLIN2-ARCH/merlin2) runs each action as a node of its own, built on
``merlin2_fsm_action.Merlin2FsmAction`` (MERLIN2's action base, ``merlin2_action.Merlin2Action``,
plus a YASMIN state machine) with its PDDL definition as KANT DTOs (``kant_dto``). The adapter
here wraps each :class:`~merlin2_sailor_behaviors.actions.SailorAction` in that class, so the same
PDDL action and the same state machine register and run in MERLIN2 (its knowledge base, planner
and executor) instead of the ``behaviors`` node and this project's mission runtime.

Nothing in this package imports MERLIN2 at import time: :func:`sailor_fsm_action_class` imports
``merlin2_fsm_action`` and ``kant_dto`` when called and raises
:class:`~merlin2_sailor.errors.DependencyError`, saying what to build, when they are missing.
Where real YASMIN is installed (as in any MERLIN2 workspace), the behaviours' states already are
YASMIN states (see :mod:`merlin2_sailor_behaviors.state_machines`), so they nest in MERLIN2's
machine unchanged.

Run every SAILOR action as MERLIN2 actions with
``python -m merlin2_sailor_behaviors.merlin2.run [action ...]`` in a sourced MERLIN2 workspace.
"""

from merlin2_sailor_behaviors.merlin2.fsm_action import (
    GOAL_KEY,
    ActionDtos,
    ContextFactory,
    Merlin2Api,
    action_dtos,
    load_merlin2,
    sailor_fsm_action_class,
)

__all__ = [
    "GOAL_KEY",
    "ActionDtos",
    "ContextFactory",
    "Merlin2Api",
    "action_dtos",
    "load_merlin2",
    "sailor_fsm_action_class",
]
