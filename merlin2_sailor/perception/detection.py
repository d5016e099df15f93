"""One object found by a detector in one image: the currency between detector, tracker and percepts.

Every detector backend returns these, the tracker returns them with ``tracker_id`` filled in, and
the percept generator turns them into percepts; so a new backend only has to produce this.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.contract.percept import BoundingBox2D


@dataclass(frozen=True, slots=True, eq=False)
class Detection:
    """A detected object: its class, the detector's confidence and where it is in the image.

    ``box`` is in pixels of the image the detector saw (edge coordinates: the image spans
    [0, width] x [0, height]). ``mask``, when the backend segments, is an (H, W) boolean image.
    ``tracker_id`` is empty until a tracker has confirmed the detection as part of a track, and an
    empty id means "no identity evidence", never a fresh identity.
    """

    class_id: int
    class_name: str
    score: float
    box: BoundingBox2D
    mask: np.ndarray | None = None
    tracker_id: str = ""


def corners_array(detections: Sequence[Detection]) -> np.ndarray:
    """Stack the boxes of ``detections`` into an (N, 4) array of (x_min, y_min, x_max, y_max)."""
    if not detections:
        return np.empty((0, 4), dtype=np.float64)
    return np.array([detection.box.corners for detection in detections], dtype=np.float64)
