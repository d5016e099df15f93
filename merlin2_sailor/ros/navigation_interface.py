"""Which NavigateToPose the robot speaks: Nav2's where nav2_msgs is installed, else the project's.

A robot with Nav2 has ``nav2_msgs``; its ``navigate_to_pose`` server only speaks
``nav2_msgs/action/NavigateToPose``, and MERLIN2's waypoint navigation calls that type. The
project's ``merlin2_sailor_interfaces/action/NavigateToPose`` is its field-for-field subset, for
machines without Nav2. Two processes on one action name must agree on the type, so every server
and client of the project (the simulated world, the behaviours) asks this module, and the choice
follows what is installed in the one environment they share.
"""

from __future__ import annotations

import importlib
from enum import IntEnum
from functools import cache

NAV2_MODULE = "nav2_msgs.action"


class NavigationErrorCode(IntEnum):
    """The result's ``error_code``: Nav2's NONE, and the general codes Nav2 used before Jazzy split
    them per server (Jazzy's NavigateToPose declares only NONE; the field is a plain uint16)."""

    NONE = 0
    UNKNOWN = 9000
    TIMEOUT = 9002
    CANCELED = 9003


@cache
def navigate_to_pose_type() -> type:
    """Nav2's NavigateToPose action type when ``nav2_msgs`` is importable, else the project's."""
    try:
        return importlib.import_module(NAV2_MODULE).NavigateToPose
    except ImportError:
        from merlin2_sailor_interfaces.action import NavigateToPose

        return NavigateToPose


def navigation_interface_name() -> str:
    """The chosen type as ROS names it, for log lines (``nav2_msgs/action/NavigateToPose``)."""
    action_type = navigate_to_pose_type()
    return f"{action_type.__module__.split('.')[0]}/action/{action_type.__name__}"


WAYPOINT_NAVIGATION_MODULE = "waypoint_navigation_msgs.action"
WAYPOINT_NAVIGATION_ACTION = "/waypoint_navigation/navigate_to_wp"
"""Where MERLIN2's waypoint_navigation node serves NavigateToWp (its node, in its launch's namespace)."""


def waypoint_navigation_type() -> type | None:
    """MERLIN2's ``waypoint_navigation_msgs/action/NavigateToWp`` (drive to a named waypoint), None
    where it is not installed."""
    try:
        return importlib.import_module(WAYPOINT_NAVIGATION_MODULE).NavigateToWp
    except ImportError:
        return None
