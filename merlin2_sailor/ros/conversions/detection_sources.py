"""Detections from any detector: the project's DetectionArray, yolo_ros' and vision_msgs'.

A robot already runs a detector, and it publishes one of a few message types:

* ``merlin2_sailor_interfaces/DetectionArray`` (the project's ``detector`` node);
* ``yolo_msgs/DetectionArray`` (yolo_ros, the detector SAILOR's paper uses): the project's type
  copies its layout field for field (class id and name, score, tracker id, a box by centre and
  size, a mask as one polygon), so both are read by the same code;
* ``vision_msgs/Detection2DArray`` (the detector-agnostic standard: Isaac ROS, Nav2's
  ecosystem, most ROS 2 detector wrappers): a detection holds hypotheses (``class_id`` a string,
  and a score), a box by centre and size, and an ``id``. The best-scoring hypothesis is the
  detection's class; a ``class_id`` that is a name (``"cup"``) is taken as it is, and one that is
  a number is read as a COCO class in the numbering ``numeric_class_ids`` names (``coco``: YOLO's
  0-79; ``coco_tf``: TensorFlow's 1-90). There are no masks in vision_msgs.

:func:`detection_source` gives the message type and its reader for a name; each reader returns
the core's :class:`~merlin2_sailor.perception.detection.Detection` list or raises
InvalidInputError for the whole message, saying what is wrong.
"""

from __future__ import annotations

import importlib
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.errors import ConfigurationError, InvalidInputError
from merlin2_sailor.perception.coco_labels import COCO_TF_LABELS
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor.ros.conversions.perception import detections_from_message

SAILOR, YOLO_MSGS, VISION_MSGS = "sailor", "yolo_msgs", "vision_msgs"
DETECTION_TYPES = (SAILOR, YOLO_MSGS, VISION_MSGS)
NUMERIC_CLASS_IDS = ("coco", "coco_tf")
MAXIMUM_MASK_PIXELS = 8192 * 8192
"""Larger than any camera image: a mask claiming more is malformed, and rasterising it would not fit."""
_AXIS_ALIGNED_TOLERANCE = 1e-6

_MESSAGE_TYPES = {
    SAILOR: ("merlin2_sailor_interfaces.msg", "DetectionArray"),
    YOLO_MSGS: ("yolo_msgs.msg", "DetectionArray"),
    VISION_MSGS: ("vision_msgs.msg", "Detection2DArray"),
}
_COCO_NAMES = tuple(COCO_TF_LABELS[key] for key in sorted(COCO_TF_LABELS))  # YOLO's 0-79 order


@dataclass(frozen=True)
class DetectionSource:
    """A detection message type and how to read it."""

    name: str
    message_type: type
    read: Callable[[Any], list[Detection]]

    @property
    def type_name(self) -> str:
        module, name = _MESSAGE_TYPES[self.name]
        return f"{module.split('.')[0]}/msg/{name}"


def detection_source(name: str, numeric_class_ids: str = "coco") -> DetectionSource:
    """The detection message type called ``name`` (one of :data:`DETECTION_TYPES`) and its reader.

    Raises:
        ConfigurationError: an unknown name or numbering, or a type whose package is not installed.
    """
    if name not in _MESSAGE_TYPES:
        raise ConfigurationError(f"detections type '{name}' is not one of {list(DETECTION_TYPES)}")
    if numeric_class_ids not in NUMERIC_CLASS_IDS:
        raise ConfigurationError(
            f"numeric class ids '{numeric_class_ids}' are not one of {list(NUMERIC_CLASS_IDS)}")
    module_name, type_name = _MESSAGE_TYPES[name]
    try:
        message_type = getattr(importlib.import_module(module_name), type_name)
    except ImportError as error:
        raise ConfigurationError(
            f"detections of type {module_name.split('.')[0]}/msg/{type_name} need the "
            f"{module_name.split('.')[0]} package, which is not installed ({error}); install it (on a robot: "
            f"apt install ros-jazzy-{module_name.split('.')[0].replace('_', '-')}) or choose another detections type"
        ) from error
    if name == VISION_MSGS:
        return DetectionSource(name, message_type, lambda message: vision_detections(message, numeric_class_ids))
    return DetectionSource(name, message_type, yolo_layout_detections)


def yolo_layout_detections(message: Any) -> list[Detection]:
    """The project's DetectionArray or yolo_msgs' (the same layout)."""
    for detection in message.detections:
        mask = detection.mask
        if mask.data and mask.height * mask.width > MAXIMUM_MASK_PIXELS:
            raise InvalidInputError(
                f"detection '{detection.class_name}' has a mask of {mask.width}x{mask.height} pixels, "
                f"more than the {MAXIMUM_MASK_PIXELS} of any camera image"
            )
    return detections_from_message(message)


def vision_detections(message: Any, numeric_class_ids: str = "coco") -> list[Detection]:
    """Every detection of a vision_msgs Detection2DArray."""
    return [vision_detection(detection, numeric_class_ids) for detection in message.detections]


def vision_detection(message: Any, numeric_class_ids: str = "coco") -> Detection:
    """One vision_msgs Detection2D: its best hypothesis, its box, its id as the tracker id."""
    if not message.results:
        raise InvalidInputError("a vision_msgs detection has no hypothesis (results is empty)")
    best = max(message.results, key=lambda result: result.hypothesis.score).hypothesis
    class_id, class_name = _class_of(best.class_id.strip(), numeric_class_ids)
    if not (math.isfinite(best.score) and 0.0 <= best.score <= 1.0):
        raise InvalidInputError(f"detection '{class_name}' has score {best.score}, not in [0, 1]")
    box = message.bbox
    values = (box.center.position.x, box.center.position.y, box.size_x, box.size_y, box.center.theta)
    if not all(math.isfinite(value) for value in values):
        raise InvalidInputError(f"detection '{class_name}' has a non-finite box {values[:4]}")
    if box.size_x <= 0.0 or box.size_y <= 0.0:
        raise InvalidInputError(f"detection '{class_name}' has an empty box ({box.size_x} x {box.size_y} pixels)")
    if abs(box.center.theta) > _AXIS_ALIGNED_TOLERANCE:
        raise InvalidInputError(
            f"detection '{class_name}' has a rotated box (theta {box.center.theta} rad); only axis-aligned boxes "
            "are supported")
    return Detection(
        class_id=class_id,
        class_name=class_name,
        score=float(best.score),
        box=BoundingBox2D(box.center.position.x, box.center.position.y, box.size_x, box.size_y),
        tracker_id=message.id,
    )


def _class_of(class_id: str, numeric_class_ids: str) -> tuple[int, str]:
    """(numeric id, name) of a vision_msgs class id: a name as it is (numeric id -1), or a number
    read in the COCO numbering given."""
    if not class_id:
        raise InvalidInputError("a vision_msgs hypothesis has an empty class_id")
    try:
        number = int(class_id)
    except ValueError:
        return -1, class_id
    if numeric_class_ids == "coco_tf":
        if number not in COCO_TF_LABELS:
            raise InvalidInputError(f"class id {number} is not a COCO class in TensorFlow's 1-90 numbering")
        return number, COCO_TF_LABELS[number]
    if not 0 <= number < len(_COCO_NAMES):
        raise InvalidInputError(f"class id {number} is not a COCO class in YOLO's 0-79 numbering")
    return number, _COCO_NAMES[number]
