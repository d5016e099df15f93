"""Manipulation behaviours: bring (pick, carry, place) with the expectations that let anchoring
follow an object the camera cannot see (ROS-free)."""

from merlin2_sailor_behaviors.manipulation.bring import BRING_ACTION, BRING_SOURCE, bring_state_machine

__all__ = ["BRING_ACTION", "BRING_SOURCE", "bring_state_machine"]
