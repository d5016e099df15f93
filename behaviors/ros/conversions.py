"""The behaviours' message conversions: anchors to reports, planar poses to and from PoseStamped.

The project's general conversions live in :mod:`merlin2_sailor.ros.conversions`; these are the
few only behaviours need, on top of its anchor-state table and stamp helpers.
"""

from __future__ import annotations

import math

from geometry_msgs.msg import Point, PoseStamped

from merlin2_sailor.ros.conversions import stamp_to_seconds
from merlin2_sailor.ros.conversions.anchoring import STATE_FROM_MESSAGE
from merlin2_sailor_behaviors.actions.clients import AnchorReport, Pose2D
from merlin2_sailor_behaviors.actions.errors import BehaviorError
from merlin2_sailor_interfaces.msg import Anchor as AnchorMessage


def anchor_report(message: AnchorMessage) -> AnchorReport:
    """An Anchor message as the report behaviours read.

    Raises:
        BehaviorError: an unknown state constant or a position that is not finite.
    """
    state = STATE_FROM_MESSAGE.get(message.state)
    if state is None:
        raise BehaviorError(f"anchor {message.symbol!r} has an unknown state {message.state}")
    position = (float(message.position.x), float(message.position.y), float(message.position.z))
    if not all(math.isfinite(value) for value in position):
        raise BehaviorError(f"anchor {message.symbol!r} has a position that is not finite: {list(position)}")
    return AnchorReport(
        symbol=message.symbol,
        class_name=message.class_name,
        state=state,
        position=position,
        last_seen=stamp_to_seconds(message.last_seen),
        times_seen=int(message.times_seen),
        indistinguishable_from=tuple(str(symbol) for symbol in message.indistinguishable_from),
        found_by_look_alone=str(message.found_by_look_alone),
    )


def point_message(point: tuple[float, float, float]) -> Point:
    x, y, z = (float(value) for value in point)
    return Point(x=x, y=y, z=z)


def pose_stamped(pose: Pose2D, frame_id: str) -> PoseStamped:
    """A planar pose as a PoseStamped on the floor (z = 0), rotated about z by its yaw."""
    message = PoseStamped()
    message.header.frame_id = frame_id
    message.pose.position.x, message.pose.position.y = float(pose.x), float(pose.y)
    message.pose.orientation.z = math.sin(pose.yaw / 2.0)
    message.pose.orientation.w = math.cos(pose.yaw / 2.0)
    return message


def planar_pose(message: PoseStamped) -> Pose2D:
    """The position and heading (yaw about z) of a PoseStamped.

    Raises:
        BehaviorError: a value is not finite, or the orientation is a zero quaternion.
    """
    position, q = message.pose.position, message.pose.orientation
    norm = math.sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w)
    if not math.isfinite(norm) or norm < 1e-9:
        raise BehaviorError(f"a robot pose has no valid orientation ({q.x}, {q.y}, {q.z}, {q.w})")
    x, y, z, w = q.x / norm, q.y / norm, q.z / norm, q.w / norm
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return Pose2D(float(position.x), float(position.y), yaw)
