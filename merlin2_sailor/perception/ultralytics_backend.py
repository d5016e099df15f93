"""YOLO through Ultralytics, for deployments that have it and a weights file of their own.

Ultralytics is optional and heavy (it needs a torch/torchvision pair that the default install
does not carry) and, left to its defaults, downloads weights and installs packages on first use.
A robot must never do that mid-mission, so this backend insists on a local weights file and
switches Ultralytics to offline mode before importing it. Install ``ultralytics-opencv-headless``,
not plain ``ultralytics``, which pulls the non-headless OpenCV.
"""

from __future__ import annotations

import importlib.util
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.errors import ConfigurationError, DependencyError
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor.perception.detector import Detector, check_rgb_image


@dataclass(frozen=True, slots=True)
class UltralyticsConfig:
    """Options of the Ultralytics YOLO detector.

    ``weights_path``: a local ``.pt`` (or exported) model file; required, never downloaded.
    ``score_threshold``: detections below this confidence are discarded.
    ``overlap_threshold``: IoU of Ultralytics' own non-maximum suppression.
    ``device``: torch device string ("cpu", "cuda:0").
    ``image_size``: the network input size in pixels.
    """

    weights_path: str = ""
    score_threshold: float = 0.5
    overlap_threshold: float = 0.7
    device: str = "cpu"
    image_size: int = 640

    def __post_init__(self) -> None:
        if not self.weights_path:
            raise ConfigurationError(
                "The ultralytics detector needs weights_path, a local YOLO weights file; it never downloads one."
            )
        if not (0.0 <= self.score_threshold <= 1.0):
            raise ConfigurationError(f"score_threshold must be in [0, 1], got {self.score_threshold}.")
        if not (0.0 < self.overlap_threshold <= 1.0):
            raise ConfigurationError(f"overlap_threshold must be in (0, 1], got {self.overlap_threshold}.")
        if self.image_size < 32:
            raise ConfigurationError(f"image_size must be at least 32 pixels, got {self.image_size}.")


class UltralyticsDetector(Detector):
    """YOLO (detection or segmentation) models; class names come from the model file."""

    config_class = UltralyticsConfig

    def __init__(self, config: UltralyticsConfig, report: Callable[[str], None] | None = None) -> None:
        super().__init__(config, report)
        weights = Path(config.weights_path).expanduser()
        if not weights.is_file():
            raise ConfigurationError(
                f"YOLO weights file {weights} does not exist; copy the model onto the robot and set weights_path."
            )
        if importlib.util.find_spec("ultralytics") is None:
            raise DependencyError(
                "The ultralytics detector needs the ultralytics package; install ultralytics-opencv-headless "
                "together with a matching torch and torchvision, or use the ssd_mobilenet backend."
            )
        # Ultralytics reads these at import time: no hub checks, no pip installs, no downloads.
        os.environ["YOLO_OFFLINE"] = "1"
        os.environ["YOLO_AUTOINSTALL"] = "False"
        from ultralytics import YOLO

        self._model = YOLO(str(weights))

    def detect(self, image_rgb: np.ndarray) -> list[Detection]:
        image = check_rgb_image(image_rgb)
        # Ultralytics treats numpy images as BGR (OpenCV's order), so reverse the channels.
        result = self._model.predict(
            np.ascontiguousarray(image[:, :, ::-1]),
            conf=self.config.score_threshold,
            iou=self.config.overlap_threshold,
            imgsz=self.config.image_size,
            device=self.config.device,
            verbose=False,
        )[0]
        names = result.names
        boxes = result.boxes
        corners = boxes.xyxy.cpu().numpy().astype(np.float64)
        scores = boxes.conf.cpu().numpy().astype(np.float64)
        class_ids = boxes.cls.cpu().numpy().astype(int)
        masks = None
        if result.masks is not None:
            # ``masks.data`` is at the letterboxed network resolution; the polygons in ``masks.xy``
            # are already in image pixels, so rasterising them gives masks aligned with the image.
            import cv2

            masks = np.zeros((len(corners), image.shape[0], image.shape[1]), dtype=np.uint8)
            for index, polygon in enumerate(result.masks.xy):
                if len(polygon) >= 3:
                    cv2.fillPoly(masks[index], [np.round(polygon).astype(np.int32)], 1)
            masks = masks.astype(bool)
        detections = [
            Detection(
                class_id=int(class_id),
                class_name=str(names[int(class_id)]),
                score=float(score),
                box=BoundingBox2D.from_corners(*(float(value) for value in box)),
                mask=None if masks is None else masks[index],
            )
            for index, (box, score, class_id) in enumerate(zip(corners, scores, class_ids, strict=True))
        ]
        return sorted(detections, key=lambda detection: detection.score, reverse=True)
