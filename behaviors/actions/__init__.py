"""The MERLIN2-style action base: a PDDL action paired with the state machine that carries it out.

ROS-free. :class:`SailorAction` (the pair, with knowledge-base registration),
:mod:`.domain` (SAILOR's PDDL domain, as data), the ports behaviours talk to the robot through
(:mod:`.clients`), the map's places (:mod:`.places`), the context a state machine is built with
(:mod:`.context`) and the states behaviours are assembled from (:mod:`.states`). Every action by
name is in :mod:`merlin2_sailor_behaviors.catalogue`, one level above the behaviours it lists.
"""

from merlin2_sailor_behaviors.actions.clients import (
    AnchoringPort,
    AnchorReport,
    GraspPort,
    GraspResult,
    NavigationPort,
    NavigationResult,
    NavigationStatus,
    Pose2D,
)
from merlin2_sailor_behaviors.actions.context import BehaviorConfig, BehaviorContext
from merlin2_sailor_behaviors.actions.errors import BehaviorError
from merlin2_sailor_behaviors.actions.keys import (
    CLASS_NAME_KEY,
    FOUND_AT_KEY,
    FOUND_SYMBOL_KEY,
    PLAN_STEP_KEY,
    REASON_KEY,
    WARNINGS_KEY,
)
from merlin2_sailor_behaviors.actions.places import Place, Places
from merlin2_sailor_behaviors.actions.progress import active_state_path
from merlin2_sailor_behaviors.actions.sailor_action import SailorAction, StateMachineFactory

__all__ = [
    "CLASS_NAME_KEY",
    "FOUND_AT_KEY",
    "FOUND_SYMBOL_KEY",
    "PLAN_STEP_KEY",
    "REASON_KEY",
    "WARNINGS_KEY",
    "AnchorReport",
    "AnchoringPort",
    "BehaviorConfig",
    "BehaviorContext",
    "BehaviorError",
    "GraspPort",
    "GraspResult",
    "NavigationPort",
    "NavigationResult",
    "NavigationStatus",
    "Place",
    "Places",
    "Pose2D",
    "SailorAction",
    "StateMachineFactory",
    "active_state_path",
]
