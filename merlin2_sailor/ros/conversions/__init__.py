"""Every conversion between ROS messages and the core's Python objects, in one package.

Nodes import from here only; each submodule covers one family of messages:
:mod:`.sensors` (images, depth, camera info, stamps), :mod:`.message_types` (classes by type name)
and :mod:`.knowledge` (the PDDL model and knowledge-base changes).
"""

from merlin2_sailor.ros.conversions.message_types import message_class
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
    "camera_info_message",
    "depth_to_metres",
    "image_to_array",
    "message_class",
    "seconds_to_stamp",
    "stamp_to_seconds",
]
