"""The camera's pose from TF, as every ROS node gets it: /tf and /tf_static through tf2_ros.

A robot publishes its frames on TF (the map -> odom -> base_link chain from localisation and
odometry, base_link -> camera_link -> camera_color_optical_frame from its description), and a
camera driver stamps every image with its optical frame. :class:`TfCameraPoses` looks up that
frame in the world frame at the image's stamp. When it cannot (a frame nobody publishes, a
transform older or newer than the stamp), it raises InvalidInputError with one sentence naming
both frames, the stamp asked for and the latest stamp TF has for that pair, and counts the
failure; the caller drops the frame and logs the sentence (rate-limited). Lookups never wait: the
transform for an image normally arrives before its detections, and a wait in a callback would
hold the executor that fills the TF buffer.

tf2_ros is not on PyPI: on a robot it comes with ROS 2; here it is built from SAILOR_UPSTREAM
for the tests (scripts/upstream_env.sh). Where it is missing, asking for TF is a clear error.
"""

from __future__ import annotations

import threading
from typing import Any

from rclpy.node import Node
from rclpy.time import Time

from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import DependencyError, InvalidInputError
from merlin2_sailor.ros.conversions import transform_to_pose


class TfCameraPoses:
    """Poses of camera frames in ``world_frame``, from a TF buffer filled on ``node``."""

    def __init__(self, node: Node, world_frame: str, option: str = "pose_source 'tf'",
                 alternative: str = "pose_source 'topic'") -> None:
        try:
            import tf2_ros
        except ImportError as error:
            raise DependencyError(
                f"{option} needs tf2_ros, which is not installable from PyPI (no wheel exists); run under a ROS 2 "
                "Jazzy installation (apt or source), or take the camera pose from a topic "
                f"({alternative})"
            ) from error
        self._tf2_ros = tf2_ros
        self.world_frame = world_frame
        self._buffer = tf2_ros.Buffer()
        self._listener = tf2_ros.TransformListener(self._buffer, node)
        self._lock = threading.Lock()
        self.failures = 0
        """Lookups that failed since the start (each a frame dropped by the caller)."""

    def lookup(self, camera_frame: str, stamp: Any) -> Pose:
        """The pose of ``camera_frame`` in the world frame at ``stamp`` (a builtin_interfaces Time).

        Raises:
            InvalidInputError: no such transform at that stamp; the message says why and what TF has.
        """
        if not camera_frame:
            self._count()
            raise InvalidInputError("the message has no frame_id: its camera frame is unknown to TF")
        try:
            transform = self._buffer.lookup_transform(self.world_frame, camera_frame, Time.from_msg(stamp))
        except self._tf2_ros.TransformException as error:
            failures = self._count()
            asked = Time.from_msg(stamp).nanoseconds * 1e-9
            raise InvalidInputError(
                f"no transform from '{camera_frame}' to '{self.world_frame}' at {asked:.3f} "
                f"({self._latest(camera_frame)}): {_first_line(error)} [{failures} frame(s) without a transform "
                "since the start]"
            ) from error
        return transform_to_pose(transform)

    def _latest(self, camera_frame: str) -> str:
        try:
            latest = self._buffer.lookup_transform(self.world_frame, camera_frame, Time())
        except self._tf2_ros.TransformException:
            return "TF has never connected these frames"
        stamp = Time.from_msg(latest.header.stamp).nanoseconds * 1e-9
        return f"the latest transform between them is at {stamp:.3f}"

    def _count(self) -> int:
        with self._lock:
            self.failures += 1
            return self.failures


def _first_line(error: Exception) -> str:
    text = str(error).strip()
    return text.splitlines()[0] if text else type(error).__name__
