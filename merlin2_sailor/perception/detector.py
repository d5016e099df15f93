"""The detector stage's port: an RGB image in, a list of detections out.

Backends implement :class:`Detector`; they are chosen by name in :mod:`.detector_registry`, the
table above them, which imports only the one chosen.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable
from typing import Any, ClassVar

import numpy as np

from merlin2_sailor.errors import InvalidInputError
from merlin2_sailor.perception.detection import Detection


class Detector(ABC):
    """Finds objects in one RGB image; one verb, ``detect``.

    Subclasses set ``config_class`` to the frozen dataclass their constructor takes, so
    :func:`~.detector_registry.create_detector` can build and validate it from plain parameters (a YAML mapping).
    """

    config_class: ClassVar[type]

    def __init__(self, config: Any, report: Callable[[str], None] | None = None) -> None:
        """``report`` hears what the owner should log once (a model converted, a device replaced)."""
        self.config = config

    @property
    def threads(self) -> int:
        """Threads the backend runs its network with (0 when it does not say)."""
        return 0

    @abstractmethod
    def detect(self, image_rgb: np.ndarray) -> list[Detection]:
        """Return the objects found in an (H, W, 3) uint8 RGB image, best score first."""


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
