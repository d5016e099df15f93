"""Detections in the message types of other detectors (yolo_ros' yolo_msgs, vision_msgs), built from
the core's Detection, for tests. Import only where those packages are (SAILOR_UPSTREAM)."""

from __future__ import annotations

from std_msgs.msg import Header

from merlin2_sailor.perception.detection import Detection
from merlin2_sailor.ros.conversions import mask_to_message

HEADER = Header(frame_id="camera_color_optical_frame")


def yolo_array(detections: list[Detection]):  # noqa: ANN201 - a yolo_msgs DetectionArray
    from yolo_msgs.msg import BoundingBox2D as YoloBox
    from yolo_msgs.msg import Detection as YoloDetection
    from yolo_msgs.msg import DetectionArray as YoloArray

    array = YoloArray(header=HEADER)
    for detection in detections:
        box = YoloBox()
        box.center.position.x, box.center.position.y = detection.box.center_x, detection.box.center_y
        box.size.x, box.size.y = detection.box.width, detection.box.height
        message = YoloDetection(class_id=detection.class_id, class_name=detection.class_name, score=detection.score,
                                id=detection.tracker_id, bbox=box)
        if detection.mask is not None:
            own = mask_to_message(detection.mask)
            message.mask.height, message.mask.width = own.height, own.width
            message.mask.data = [_yolo_point(p) for p in own.data]
        array.detections.append(message)
    return array


def _yolo_point(point):  # noqa: ANN001, ANN202
    from yolo_msgs.msg import Point2D

    return Point2D(x=point.x, y=point.y)


def vision_array(detections: list[Detection], class_ids: list[str] | None = None):  # noqa: ANN201
    from vision_msgs.msg import Detection2D, Detection2DArray, ObjectHypothesisWithPose

    array = Detection2DArray(header=HEADER)
    for index, detection in enumerate(detections):
        message = Detection2D(header=HEADER, id=detection.tracker_id)
        message.bbox.center.position.x, message.bbox.center.position.y = detection.box.center_x, detection.box.center_y
        message.bbox.size_x, message.bbox.size_y = detection.box.width, detection.box.height
        decoy = ObjectHypothesisWithPose()  # a weaker hypothesis: the best one is the class
        decoy.hypothesis.class_id, decoy.hypothesis.score = "dog", detection.score / 2
        best = ObjectHypothesisWithPose()
        best.hypothesis.class_id = class_ids[index] if class_ids else detection.class_name
        best.hypothesis.score = detection.score
        message.results = [decoy, best]
        array.detections.append(message)
    return array
