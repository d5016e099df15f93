"""Detections from any detector: the project's DetectionArray, yolo_ros' yolo_msgs and vision_msgs.

The real yolo_msgs and vision_msgs are built from SAILOR_UPSTREAM (scripts/upstream_env.sh); the
tests that need them skip, saying why, without it.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.errors import ConfigurationError, InvalidInputError
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor.ros.conversions import detection_to_message
from merlin2_sailor.ros.conversions.detection_sources import (
    _MESSAGE_TYPES,
    DETECTION_TYPES,
    detection_source,
)
from merlin2_sailor_interfaces.msg import DetectionArray

sys.path.insert(0, str(Path(__file__).resolve().parent))  # test/ros is not a package: its helpers
from detector_messages import HEADER, vision_array, yolo_array  # noqa: E402

CUP = Detection(41, "cup", 0.83, BoundingBox2D(120.5, 88.0, 40.0, 52.0), tracker_id="7")
BOOK = Detection(73, "book", 0.61, BoundingBox2D(300.0, 200.0, 80.0, 20.0))


@pytest.fixture
def real_types(upstream_stack) -> None:
    upstream_stack("yolo_msgs.msg", "vision_msgs.msg")


def test_the_three_types_give_the_same_detections(real_types) -> None:
    mask = np.zeros((240, 320), dtype=bool)
    mask[70:100, 105:135] = True
    cup = Detection(CUP.class_id, CUP.class_name, CUP.score, CUP.box, mask=mask, tracker_id=CUP.tracker_id)
    own = detection_source("sailor").read(DetectionArray(header=HEADER, detections=[detection_to_message(cup),
                                                                                      detection_to_message(BOOK)]))
    yolo = detection_source("yolo_msgs").read(yolo_array([cup, BOOK]))
    vision = detection_source("vision_msgs").read(vision_array([cup, BOOK]))
    for read in (own, yolo):
        assert [(d.class_id, d.class_name, d.score, d.box, d.tracker_id) for d in read] == [
            (41, "cup", 0.83, CUP.box, "7"), (73, "book", 0.61, BOOK.box, "")]
    np.testing.assert_array_equal(own[0].mask, yolo[0].mask)  # yolo_ros' masks are read too
    # vision_msgs has no numeric id beside a class name, and no masks.
    assert [(d.class_id, d.class_name, d.score, d.box, d.tracker_id, d.mask) for d in vision] == [
        (-1, "cup", 0.83, CUP.box, "7", None), (-1, "book", 0.61, BOOK.box, "", None)]


@pytest.mark.parametrize(("numbering", "class_ids"), [("coco", ["41", "73"]), ("coco_tf", ["47", "84"])])
def test_numeric_vision_class_ids_are_read_in_the_coco_numbering_given(real_types, numbering, class_ids) -> None:
    read = detection_source("vision_msgs", numbering).read(vision_array([CUP, BOOK], class_ids))
    assert [(d.class_id, d.class_name) for d in read] == [(int(class_ids[0]), "cup"), (int(class_ids[1]), "book")]


def test_malformed_vision_detections_are_refused_with_the_reason(real_types) -> None:
    source = detection_source("vision_msgs")
    cases = {
        "no hypothesis": lambda m: m.detections[0].results.clear(),
        "not a COCO class": lambda m: setattr(m.detections[0].results[1].hypothesis, "class_id", "95"),
        "empty class_id": lambda m: setattr(m.detections[0].results[1].hypothesis, "class_id", " "),
        "empty box": lambda m: setattr(m.detections[0].bbox, "size_x", 0.0),
        "rotated box": lambda m: setattr(m.detections[0].bbox.center, "theta", 0.3),
        "non-finite box": lambda m: setattr(m.detections[0].bbox.center.position, "x", float("nan")),
    }
    for reason, spoil in cases.items():
        message = vision_array([CUP])
        spoil(message)
        with pytest.raises(InvalidInputError, match=reason):
            source.read(message)


def test_unknown_types_and_missing_packages_are_configuration_errors(monkeypatch) -> None:
    with pytest.raises(ConfigurationError, match="not one of"):
        detection_source("darknet_msgs")
    with pytest.raises(ConfigurationError, match="numeric class ids"):
        detection_source("vision_msgs", "imagenet")
    monkeypatch.setitem(_MESSAGE_TYPES, "vision_msgs", ("vision_msgs_not_installed.msg", "Detection2DArray"))
    with pytest.raises(ConfigurationError, match="not installed"):
        detection_source("vision_msgs")
    assert set(DETECTION_TYPES) == set(_MESSAGE_TYPES)
