"""Missions: goals as typed by people, the running account an operator reads, and the mission node."""

from merlin2_sailor_behaviors.mission.account import AnchorEventWording, describe_fact_changes
from merlin2_sailor_behaviors.mission.goals import parse_goal, parse_goals

__all__ = ["AnchorEventWording", "describe_fact_changes", "parse_goal", "parse_goals"]
