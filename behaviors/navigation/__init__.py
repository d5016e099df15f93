"""Moving and looking: MERLIN2's navigation with SAILOR's expectations, explore, approach_object.

ROS-free state machines over the ports of :mod:`merlin2_sailor_behaviors.actions.clients`.
"""

from merlin2_sailor_behaviors.navigation.approach_object import (
    APPROACH_OBJECT_ACTION,
    approach_object_state_machine,
)
from merlin2_sailor_behaviors.navigation.explore import EXPLORE_ACTION, explore_state_machine
from merlin2_sailor_behaviors.navigation.navigation import (
    NAVIGATION_ACTION,
    NAVIGATION_SOURCE,
    navigation_state_machine,
)

__all__ = [
    "APPROACH_OBJECT_ACTION",
    "EXPLORE_ACTION",
    "NAVIGATION_ACTION",
    "NAVIGATION_SOURCE",
    "approach_object_state_machine",
    "explore_state_machine",
    "navigation_state_machine",
]
