"""rgbd_player: publish real RGB-D frames and the camera's pose, like a camera driver would.

It stands in for an RGB-D camera when none is attached: colour (rgb8), registered depth (32FC1
metres or 16UC1 millimetres), CameraInfo, and the camera's pose in the world frame, all with the
same stamp, at a fixed rate, with sensor-data QoS. Frames come from the sources in
:mod:`merlin2_sailor_demos.rgbd_sources`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from geometry_msgs.msg import PoseStamped
from rclpy.node import Node
from sensor_msgs.msg import CameraInfo, Image
from std_msgs.msg import Header

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.ros.conversions import array_to_image, camera_info_message
from merlin2_sailor.ros.node_runner import run_node
from merlin2_sailor.ros.parameters import declare_parameter
from merlin2_sailor.ros.qos import SENSOR_DATA
from merlin2_sailor_demos.rgbd_sources import RgbdFrame, load_source

NODE_NAME = "rgbd_player"

# The camera 1 m above the world origin, looking along the world's +x axis: the optical frame
# (z forward, x right, y down) rotated into a z-up world (x forward, y left).
DEFAULT_CAMERA_POSE = [0.0, 0.0, 1.0, -0.5, 0.5, -0.5, 0.5]


@dataclass
class _FrameMessages:
    """The messages of one frame, converted once; publishing only restamps them."""

    color: Image
    depth: Image
    info: CameraInfo


class RgbdPlayerNode(Node):
    def __init__(self) -> None:
        super().__init__(NODE_NAME)
        source = declare_parameter(self, "source", "motorcycle", "Name of the RGB-D frame source.")
        rate_hz = declare_parameter(self, "rate_hz", 15.0, "Frames per second.", minimum=0.1, maximum=120.0)
        self._camera_frame = declare_parameter(
            self, "camera_frame", "camera_color_optical_frame", "frame_id of the images (optical frame)."
        )
        self._world_frame = declare_parameter(
            self, "world_frame", "map", "Fixed frame in which the camera pose is published."
        )
        self._depth_encoding = declare_parameter(
            self, "depth_encoding", "32FC1", "Depth encoding: 32FC1 (metres) or 16UC1 (millimetres)."
        )
        if self._depth_encoding not in ("32FC1", "16UC1"):
            raise ConfigurationError("depth_encoding must be 32FC1 or 16UC1")
        pose = declare_parameter(
            self, "camera_pose", DEFAULT_CAMERA_POSE,
            "Camera pose in world_frame: x, y, z (metres), qx, qy, qz, qw (optical frame).",
        )
        if len(pose) != 7 or not np.isclose(np.linalg.norm(pose[3:]), 1.0, atol=1e-3):
            raise ConfigurationError("camera_pose must be [x, y, z, qx, qy, qz, qw] with a unit quaternion")
        self._pose = [float(value) for value in pose]
        frames = load_source(source)
        self._frames = [self._prepare(frame) for frame in frames]
        self._next_frame = 0
        self._color_publisher = self.create_publisher(Image, "color/image_raw", SENSOR_DATA)
        self._depth_publisher = self.create_publisher(Image, "depth/image_raw", SENSOR_DATA)
        self._info_publisher = self.create_publisher(CameraInfo, "color/camera_info", SENSOR_DATA)
        self._pose_publisher = self.create_publisher(PoseStamped, "camera_pose", SENSOR_DATA)
        self.create_timer(1.0 / rate_hz, self._publish_next)
        self.get_logger().info(
            f"publishing {len(self._frames)} frame(s) of '{source}' at {rate_hz:g} Hz "
            f"({frames[0].width}x{frames[0].height}, depth {self._depth_encoding})"
        )

    def _prepare(self, frame: RgbdFrame) -> _FrameMessages:
        if self._depth_encoding == "16UC1":
            millimetres = np.nan_to_num(frame.depth_metres * 1000.0, nan=0.0)
            depth = array_to_image(np.clip(millimetres, 0, 65535).astype(np.uint16), "16UC1")
        else:
            depth = array_to_image(frame.depth_metres.astype(np.float32), "32FC1")
        color = array_to_image(frame.color, "rgb8")
        info = camera_info_message(frame.width, frame.height, frame.fx, frame.fy, frame.cx, frame.cy)
        return _FrameMessages(color, depth, info)

    def _publish_next(self) -> None:
        frame = self._frames[self._next_frame]
        self._next_frame = (self._next_frame + 1) % len(self._frames)
        header = Header(stamp=self.get_clock().now().to_msg(), frame_id=self._camera_frame)
        for message in (frame.color, frame.depth, frame.info):
            message.header = header
        pose = PoseStamped(header=Header(stamp=header.stamp, frame_id=self._world_frame))
        (pose.pose.position.x, pose.pose.position.y, pose.pose.position.z,
         pose.pose.orientation.x, pose.pose.orientation.y, pose.pose.orientation.z,
         pose.pose.orientation.w) = self._pose
        self._color_publisher.publish(frame.color)
        self._depth_publisher.publish(frame.depth)
        self._info_publisher.publish(frame.info)
        self._pose_publisher.publish(pose)


def main(argv: Sequence[str] | None = None) -> int:
    return run_node(RgbdPlayerNode, argv)


if __name__ == "__main__":
    raise SystemExit(main())
