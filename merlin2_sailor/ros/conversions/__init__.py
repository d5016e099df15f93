"""Every conversion between ROS messages and the core's Python objects, in one package.

Nodes import from here only; each submodule covers one family of messages:
:mod:`.sensors` (images, depth, camera info, stamps), :mod:`.message_types` (classes by type name),
:mod:`.knowledge` (the PDDL model and knowledge-base changes) and :mod:`.perception` (detections,
percepts, intrinsics, camera poses, point clouds and their markers).
"""

from merlin2_sailor.ros.conversions.message_types import message_class
from merlin2_sailor.ros.conversions.perception import (
    array_to_point_cloud,
    camera_info_to_intrinsics,
    detection_from_message,
    detection_to_message,
    detections_from_message,
    detections_to_message,
    image_to_rgb,
    mask_from_message,
    mask_to_message,
    odometry_to_camera_pose,
    percept_from_message,
    percept_markers,
    percept_to_message,
    percepts_from_message,
    percepts_to_message,
    point_cloud_to_array,
    pose_from_message,
    pose_to_message,
    transform_to_pose,
)
from merlin2_sailor.ros.conversions.sensors import (
    IMAGE_ENCODINGS,
    array_to_image,
    camera_info_message,
    depth_to_metres,
    image_to_array,
    seconds_to_stamp,
    stamp_to_seconds,
)

__all__ = [
    "IMAGE_ENCODINGS",
    "array_to_image",
    "array_to_point_cloud",
    "camera_info_message",
    "camera_info_to_intrinsics",
    "depth_to_metres",
    "detection_from_message",
    "detection_to_message",
    "detections_from_message",
    "detections_to_message",
    "image_to_array",
    "image_to_rgb",
    "mask_from_message",
    "mask_to_message",
    "message_class",
    "odometry_to_camera_pose",
    "percept_from_message",
    "percept_markers",
    "percept_to_message",
    "percepts_from_message",
    "percepts_to_message",
    "point_cloud_to_array",
    "pose_from_message",
    "pose_to_message",
    "seconds_to_stamp",
    "stamp_to_seconds",
    "transform_to_pose",
]
