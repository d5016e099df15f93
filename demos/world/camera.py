"""The robot's RGB-D camera: pinhole intrinsics and a fixed, level mount on the robot.

The camera looks straight ahead, level with the floor, ``mount_height`` above it. A level
camera keeps every wall edge vertical in the image, which is what lets the renderer cast one ray
per image column instead of one per pixel (see :mod:`.renderer`); a real robot's head camera
pitched down by a few degrees sees the same scene slightly shifted.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor_demos.world.geometry import Pose2D
from merlin2_sailor_demos.world.yaml_fields import Fields


@dataclass(frozen=True, slots=True)
class CameraConfig:
    """Image size and intrinsics (pixels; pixel centres at integer coordinates) and the mount (metres).

    The defaults are a Kinect-like 640x480 camera (62 x 49 degrees field of view) 1 m above the
    floor, 0.1 m ahead of the robot's centre.
    """

    width: int = 640
    height: int = 480
    fx: float = 525.0
    fy: float = 525.0
    cx: float = 319.5
    cy: float = 239.5
    mount_height: float = 1.0
    mount_forward: float = 0.1

    @property
    def intrinsics(self) -> CameraIntrinsics:
        return CameraIntrinsics(self.fx, self.fy, self.cx, self.cy, self.width, self.height)

    @property
    def horizontal_field_of_view(self) -> float:
        return 2.0 * math.atan2(max(self.cx + 0.5, self.width - 0.5 - self.cx), self.fx)

    def eye(self, robot: Pose2D) -> Pose2D:
        """The camera's position on the floor plane and its heading, for a robot at ``robot``."""
        return robot.compose(self.mount_forward, 0.0, 0.0)

    def optical_pose(self, robot: Pose2D) -> Pose:
        """The optical frame (z forward, x right, y down) in the world, as ``world <- camera``."""
        return optical_pose(self.eye(robot), self.mount_height)

    @classmethod
    def from_mapping(cls, data: Any, where: str = "camera") -> CameraConfig:
        fields = Fields(data, where, ("width", "height", "fx", "fy", "cx", "cy", "mount_height", "mount_forward"))
        width, height = fields.integer("width", 640, minimum=16), fields.integer("height", 480, minimum=16)
        return cls(
            width, height,
            fields.number("fx", 525.0 * width / 640.0, minimum=1.0),
            fields.number("fy", 525.0 * width / 640.0, minimum=1.0),
            fields.number("cx", (width - 1) / 2.0), fields.number("cy", (height - 1) / 2.0),
            fields.number("mount_height", 1.0, minimum=0.1, maximum=2.4), fields.number("mount_forward", 0.1),
        )


def optical_pose(eye: Pose2D, height: float) -> Pose:
    """``world <- optical`` for a level camera at ``eye`` (position and heading) ``height`` above the floor."""
    cos_yaw, sin_yaw = math.cos(eye.yaw), math.sin(eye.yaw)
    rotation = np.array([
        [sin_yaw, 0.0, cos_yaw],  # columns: optical x (right), y (down), z (forward) in the world
        [-cos_yaw, 0.0, sin_yaw],
        [0.0, -1.0, 0.0],
    ])
    return Pose(rotation, np.array([eye.x, eye.y, height]))
