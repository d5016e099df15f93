"""The ``motorcycle`` replay: Middlebury's Motorcycle seen by a camera sliding sideways.

The data is one real RGB-D frame: scikit-image's ``stereo_motorcycle`` left image with metric
depth from its ground-truth disparity and published calibration (f = 994.978 px,
cx = 311.193, cy = 254.877, baseline 193.001 mm, depth = f * B / (d + doffs), doffs = 31.086;
see :mod:`merlin2_sailor_demos.rgbd_sources`). The sequence is that frame seen by the same
camera translated along its x axis, the stereo baseline's direction: the offset follows
``amplitude * sin(2 pi k / views)``, so frame 0 is the real image, the camera slides
``amplitude`` to the right, back through the start and as far to the left, at ``frame_rate``.
The other views are synthesised from the real frame and its depth
(:mod:`.view_synthesis`): every object moves across the image by its own parallax while its
position in the world stays put, which is what the anchors must reproduce.

World frame: x forward, y left, z up (REP 103), the camera at ``camera_height`` above the
origin looking along x at the start. The height is nominal; the scene's own is unknown.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor_demos.replay.source import WORLD_FROM_LEVEL_OPTICAL, ReplayFrame, ReplaySource
from merlin2_sailor_demos.replay.view_synthesis import translate_view
from merlin2_sailor_demos.rgbd_sources import RgbdFrame, motorcycle_frames


@dataclass(frozen=True, slots=True)
class MotorcycleConfig:
    """``views``: frames in one back-and-forth slide; ``amplitude`` (m): the largest sideways
    offset (half the stereo baseline by default); ``camera_height`` (m): nominal."""

    views: int = 24
    amplitude: float = 0.0965
    camera_height: float = 1.0

    def __post_init__(self) -> None:
        if self.views < 1:
            raise ConfigurationError(f"motorcycle views must be at least 1, got {self.views}")
        if not (math.isfinite(self.amplitude) and 0.0 <= self.amplitude <= 0.5):
            raise ConfigurationError(f"motorcycle amplitude must be in [0, 0.5] m, got {self.amplitude}")


class MotorcycleSource(ReplaySource):
    name = "motorcycle"
    frame_rate = 10.0
    default_frames = 24
    config_class = MotorcycleConfig

    def __init__(self, config: MotorcycleConfig | None = None, frame: RgbdFrame | None = None) -> None:
        self.config = config or MotorcycleConfig()
        (self._frame,) = (frame,) if frame is not None else motorcycle_frames()
        frame = self._frame
        self._intrinsics = CameraIntrinsics(frame.fx, frame.fy, frame.cx, frame.cy, frame.width, frame.height)

    @property
    def description(self) -> str:
        return (
            "Middlebury 'Motorcycle' (scikit-image stereo_motorcycle): one real RGB image with metric depth from "
            f"its ground-truth disparity, seen by a camera sliding up to {100 * self.config.amplitude:.1f} cm "
            "sideways and back (frame 0 is the real image; the others are synthesised from it and its depth)"
        )

    @property
    def frame_count(self) -> int:
        return self.config.views

    def shift_of(self, index: int) -> float:
        """The camera's offset to the right (m) in frame ``index``."""
        return self.config.amplitude * math.sin(2.0 * math.pi * index / self.config.views)

    def camera_pose(self, index: int) -> Pose:
        start = np.array([0.0, 0.0, self.config.camera_height])
        return Pose(WORLD_FROM_LEVEL_OPTICAL, start + WORLD_FROM_LEVEL_OPTICAL @ np.array([self.shift_of(index), 0, 0]))

    def frames(self, indices: Sequence[int]) -> Iterator[ReplayFrame]:
        for index in indices:
            color, depth = translate_view(self._frame.color, self._frame.depth_metres, self._frame.fx,
                                          self.shift_of(index))
            yield ReplayFrame(index, index / self.frame_rate, color, depth, self._intrinsics, self.camera_pose(index))

    def settings(self) -> dict[str, Any]:
        return {"views": self.config.views, "amplitude_m": self.config.amplitude,
                "camera_height_m": self.config.camera_height}
