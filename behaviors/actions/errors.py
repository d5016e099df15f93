"""The error a behaviour's helpers raise when the world around it fails it.

A :class:`BehaviorError` is not a bug: the anchoring node is down, a service timed out, a
waypoint is unknown, a pose is not a number. States catch it and end ``aborted`` with its message
as the reason, so the dispatcher replans and the operator reads why; the node never crashes.
"""

from merlin2_sailor.errors import SailorError


class BehaviorError(SailorError):
    """Something a behaviour needs (a service, a place, a valid input) is not available."""
