"""find_object: SAILOR's top-down Find, searching the map for a missing object (ROS-free)."""

from merlin2_sailor_behaviors.find_object.find_object import (
    FIND_OBJECT_ACTION,
    FIND_SOURCE,
    find_object_state_machine,
)

__all__ = ["FIND_OBJECT_ACTION", "FIND_SOURCE", "find_object_state_machine"]
