"""A detector that knows the truth, then makes the mistakes a real one makes, reproducibly.

The objects in view with at least ``minimum_visible_fraction`` of their silhouette visible (see
:mod:`.visibility`) become detections of their true class, with the box of their visible part.
With ``segment``, each also carries its instance mask (the visible silhouette, from the rendered
instance image), as a segmenting detector such as YOLO-seg gives: the percept generator then
measures depth on the object's own pixels, not on the table or door frame its box also covers.
Then, from a seeded generator: each box edge moves by Gaussian noise of ``box_noise`` pixels,
each detection is missed with ``miss_probability``, and a Poisson number of false positives
(mean ``false_positives_per_frame``) of the world's classes appears at random places. Scores grow
with the visible fraction, so a half-hidden object scores lower, as it would with a real network.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor_demos.world.objects import COCO_CLASS_IDS, WorldObject
from merlin2_sailor_demos.world.visibility import Visibility

#: Scores: base + slope * visible fraction, with a little jitter, clipped to the range.
SCORE_BASE, SCORE_SLOPE, SCORE_JITTER = 0.55, 0.4, 0.03
SCORE_RANGE = (0.3, 0.99)
FALSE_POSITIVE_SCORES = (0.3, 0.6)
FALSE_POSITIVE_SIDES = (20.0, 120.0)  # pixels


@dataclass(frozen=True, slots=True)
class DetectorNoise:
    """Mistakes of the ground-truth detector; all zero gives the exact truth."""

    box_noise: float = 2.0
    miss_probability: float = 0.05
    false_positives_per_frame: float = 0.02
    minimum_visible_fraction: float = 0.3
    minimum_box_side: float = 6.0

    def __post_init__(self) -> None:
        if self.box_noise < 0.0 or self.false_positives_per_frame < 0.0 or self.minimum_box_side < 0.0:
            raise ConfigurationError("detector noise: box_noise, false_positives_per_frame and minimum_box_side "
                                     "must not be negative")
        for name in ("miss_probability", "minimum_visible_fraction"):
            if not 0.0 <= getattr(self, name) <= 1.0:
                raise ConfigurationError(f"detector noise: {name} must be in [0, 1], got {getattr(self, name)}")


class GroundTruthDetector:
    def __init__(self, noise: DetectorNoise, width: int, height: int, false_positive_classes: Sequence[str],
                 rng: np.random.Generator, segment: bool = False) -> None:
        self.noise = noise
        self.segment = segment
        self.width, self.height = width, height
        self._classes = tuple(sorted(set(false_positive_classes))) or ("cup",)
        self._rng = rng

    def detect(self, objects: Sequence[WorldObject], visible: Sequence[Visibility],
               instance: np.ndarray | None = None) -> list[Detection]:
        """Detections for ``visible`` (indices into ``objects``), with noise; best score first.

        ``instance`` (the rendered frame's object index per pixel, -1 elsewhere) gives the masks
        when the detector segments; false positives never have one.
        """
        noise, rng = self.noise, self._rng
        detections = []
        for seen in visible:
            if seen.fraction < noise.minimum_visible_fraction:
                continue
            item = objects[seen.index]
            if item.carried or rng.random() < noise.miss_probability:
                continue
            box = self._jitter(seen.box)
            if box is None:
                continue
            score = float(np.clip(SCORE_BASE + SCORE_SLOPE * seen.fraction + rng.normal(0.0, SCORE_JITTER),
                                  *SCORE_RANGE))
            mask = instance == seen.index if self.segment and instance is not None else None
            detections.append(Detection(item.class_id, item.class_name, score, box, mask))
        for _ in range(int(rng.poisson(noise.false_positives_per_frame))):
            detections.append(self._false_positive())
        detections.sort(key=lambda detection: detection.score, reverse=True)
        return detections

    def _jitter(self, box: BoundingBox2D) -> BoundingBox2D | None:
        x_min, y_min, x_max, y_max = box.corners
        if self.noise.box_noise > 0.0:
            x_min, y_min, x_max, y_max = np.array([x_min, y_min, x_max, y_max]) + self._rng.normal(
                0.0, self.noise.box_noise, 4)
        x_min, x_max = np.clip([x_min, x_max], 0.0, self.width)
        y_min, y_max = np.clip([y_min, y_max], 0.0, self.height)
        if min(x_max - x_min, y_max - y_min) < max(self.noise.minimum_box_side, 1.0):
            return None
        return BoundingBox2D.from_corners(float(x_min), float(y_min), float(x_max), float(y_max))

    def _false_positive(self) -> Detection:
        rng = self._rng
        class_name = self._classes[int(rng.integers(len(self._classes)))]
        width, height = rng.uniform(*FALSE_POSITIVE_SIDES, 2)
        x, y = rng.uniform(0.0, self.width - width), rng.uniform(0.0, self.height - height)
        box = BoundingBox2D.from_corners(float(x), float(y), float(x + width), float(y + height))
        return Detection(COCO_CLASS_IDS[class_name], class_name, float(rng.uniform(*FALSE_POSITIVE_SCORES)), box)

