"""Every SAILOR action by name: what the ``behaviors`` node serves and MERLIN2 adapters register.

One level above the behaviour packages (navigation, find_object, manipulation), which build on
the action base in :mod:`merlin2_sailor_behaviors.actions`: the catalogue imports them, they
import the base, and the base imports no behaviour. A new action is a behaviour module defining
its ``SailorAction`` plus one name in the tuple below.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from types import MappingProxyType

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor_behaviors.actions.sailor_action import SailorAction
from merlin2_sailor_behaviors.find_object import FIND_OBJECT_ACTION
from merlin2_sailor_behaviors.manipulation import BRING_ACTION
from merlin2_sailor_behaviors.navigation import APPROACH_OBJECT_ACTION, EXPLORE_ACTION, NAVIGATION_ACTION

SAILOR_ACTIONS: Mapping[str, SailorAction] = MappingProxyType(
    {
        action.name: action
        for action in (NAVIGATION_ACTION, EXPLORE_ACTION, APPROACH_OBJECT_ACTION, FIND_OBJECT_ACTION, BRING_ACTION)
    }
)


def select_actions(names: Iterable[str] = ()) -> tuple[SailorAction, ...]:
    """The actions named (every one when ``names`` is empty), in the order given.

    Raises:
        ConfigurationError: a name is not one of :data:`SAILOR_ACTIONS`.
    """
    chosen = [name for name in names if name]
    if not chosen:
        return tuple(SAILOR_ACTIONS.values())
    unknown = [name for name in chosen if name not in SAILOR_ACTIONS]
    if unknown:
        raise ConfigurationError(f"unknown action(s) {unknown}; the behaviours are {sorted(SAILOR_ACTIONS)}")
    return tuple(SAILOR_ACTIONS[name] for name in dict.fromkeys(chosen))
