"""The percept: what the perceptual layer hands the anchoring layer for one detected object.

A percept is defined here, once, because it is the contract between the two layers: the
perceptual layer produces it from an RGB-D frame, the anchoring layer consumes it to decide
between acquire and reacquire. Positions are in a fixed world frame (map or odom), never in the
robot's own frame, so that the distance between a percept and an anchor means the same thing
however the robot has moved since the anchor was last seen.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True, slots=True)
class BoundingBox2D:
    """An axis-aligned box in image pixels, given by its centre and size (as YOLO publishes it)."""

    center_x: float
    center_y: float
    width: float
    height: float

    @property
    def corners(self) -> tuple[float, float, float, float]:
        """Return (x_min, y_min, x_max, y_max)."""
        half_width, half_height = self.width / 2.0, self.height / 2.0
        return (
            self.center_x - half_width,
            self.center_y - half_height,
            self.center_x + half_width,
            self.center_y + half_height,
        )

    @classmethod
    def from_corners(cls, x_min: float, y_min: float, x_max: float, y_max: float) -> BoundingBox2D:
        return cls(
            center_x=(x_min + x_max) / 2.0,
            center_y=(y_min + y_max) / 2.0,
            width=x_max - x_min,
            height=y_max - y_min,
        )


@dataclass(frozen=True, slots=True, eq=False)
class Percept:
    """One object observed in one frame, with the features the matching function uses.

    ``tracker_id`` is the multi-object tracker's id for this detection, or the empty string
    when the tracker gave none; an empty id is never evidence of identity. ``crop`` is the RGB
    image patch (H x W x 3, uint8) inside ``box``; the anchoring layer decides whether it needs
    embedding. ``embedding`` is filled only when a crop was already embedded upstream.
    ``colour`` is the colour histogram of the object's own pixels (those its 3D box was measured
    on, not the background its 2D box also covers; see
    :func:`~merlin2_sailor.perception.colour_histogram.object_colour`), or None when unknown:
    the appearance evidence every matcher can afford, since it needs no network.
    ``viewpoint`` is where the camera was (world frame) when it saw the object, or None when not
    known: the anchoring layer sets it from the frame's camera pose, since an object's colour
    depends on the side it is seen from (:mod:`~merlin2_sailor.anchoring.colour_evidence`).
    """

    class_name: str
    score: float
    box: BoundingBox2D
    position: np.ndarray  # (3,) metres, world frame
    size: np.ndarray  # (3,) metres, extent along the world axes
    stamp: float  # seconds, the image's timestamp
    crop: np.ndarray = field(default_factory=lambda: np.zeros((0, 0, 3), dtype=np.uint8))
    tracker_id: str = ""
    class_id: int = -1
    frame_id: str = "map"
    embedding: np.ndarray | None = None
    colour: np.ndarray | None = None
    viewpoint: np.ndarray | None = None
