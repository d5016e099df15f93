"""The detector stage: an RGB image in, a list of detections out, backends chosen by name.

Backends are plug-ins named by a string in the configuration and imported only when chosen, so
the OpenCV DNN model or Ultralytics (and torch behind it) cost nothing to a deployment that does
not use them, and a missing one fails with a message saying what to install.
"""

from __future__ import annotations

import dataclasses
import importlib
from abc import ABC, abstractmethod
from collections.abc import Mapping
from types import MappingProxyType
from typing import Any, ClassVar

import numpy as np

from merlin2_sailor.errors import ConfigurationError, InvalidInputError
from merlin2_sailor.perception.detection import Detection

#: Backend name -> "module:class". Kept as strings so choosing one backend imports only that one.
DETECTOR_BACKENDS = MappingProxyType(
    {
        "ssd_mobilenet": "merlin2_sailor.perception.ssd_mobilenet:SsdMobileNetDetector",
        "ultralytics": "merlin2_sailor.perception.ultralytics_backend:UltralyticsDetector",
    }
)


class Detector(ABC):
    """Finds objects in one RGB image; one verb, ``detect``.

    Subclasses set ``config_class`` to the frozen dataclass their constructor takes, so
    :func:`create_detector` can build and validate it from plain parameters (a YAML mapping).
    """

    config_class: ClassVar[type]

    def __init__(self, config: Any) -> None:
        self.config = config

    @abstractmethod
    def detect(self, image_rgb: np.ndarray) -> list[Detection]:
        """Return the objects found in an (H, W, 3) uint8 RGB image, best score first."""


def create_detector(name: str, options: Mapping[str, Any] | None = None) -> Detector:
    """Build the detector backend called ``name`` with its configuration fields ``options``."""
    if name not in DETECTOR_BACKENDS:
        raise ConfigurationError(
            f"Unknown detector backend {name!r}; choose one of {', '.join(sorted(DETECTOR_BACKENDS))}."
        )
    module_name, class_name = DETECTOR_BACKENDS[name].split(":")
    backend: type[Detector] = getattr(importlib.import_module(module_name), class_name)
    config_fields = {field.name for field in dataclasses.fields(backend.config_class)}
    unknown = set(options or {}) - config_fields
    if unknown:
        raise ConfigurationError(
            f"Detector {name!r} has no option(s) {', '.join(sorted(unknown))}; "
            f"its options are {', '.join(sorted(config_fields))}."
        )
    return backend(backend.config_class(**dict(options or {})))


def check_rgb_image(image_rgb: np.ndarray) -> np.ndarray:
    """Return ``image_rgb`` as an array after checking it is (H, W, 3) uint8, else raise."""
    image = np.asarray(image_rgb)
    if image.ndim != 3 or image.shape[2] != 3 or image.dtype != np.uint8:
        raise InvalidInputError(
            f"Detectors take an (H, W, 3) uint8 RGB image, got shape {image.shape} and dtype {image.dtype}; "
            "convert the message with encoding 'rgb8'."
        )
    if image.shape[0] == 0 or image.shape[1] == 0:
        raise InvalidInputError(f"The image is empty (shape {image.shape}).")
    return image
