"""What a replay source hands the pipeline: frames with intrinsics, a camera pose and depth.

A source is a recorded sequence (files, a video, views synthesised from a real frame). Each
:class:`ReplayFrame` carries what an RGB-D camera driver and a localisation would publish: the
RGB image, depth registered to it, the pinhole intrinsics, the camera pose in the fixed world
frame at the image stamp, and the stamp. A monocular source has no measured depth; it derives
one from the frame's detections instead (:meth:`ReplaySource.depth_for`).
"""

from __future__ import annotations

import os
from abc import ABC, abstractmethod
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from merlin2_sailor.anchoring.settings import OFFLINE_OVERRIDES, AnchoringSettings, load_anchoring_settings
from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import ConfigurationError, InvalidInputError
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor.perception.percept_generator import PerceptGeneratorConfig
from merlin2_sailor.resources import config_file

#: Rotation taking optical-frame axes (x right, y down, z forward) into a level, z-up world frame
#: (REP 103) whose x axis is the viewing direction: the camera-to-world rotation of a level camera.
WORLD_FROM_LEVEL_OPTICAL = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])


@dataclass(frozen=True, slots=True, eq=False)
class ReplayFrame:
    """One frame of a source.

    ``index`` is the frame's number in the source (0-based, before any stride); ``color`` an
    (H, W, 3) uint8 RGB image; ``depth_metres`` the (H, W) float32 depth registered to it, NaN
    where unknown, or None when the source derives depth from detections; ``camera_to_world``
    the optical frame's pose in the world frame at ``stamp`` (seconds).
    """

    index: int
    stamp: float
    color: np.ndarray
    depth_metres: np.ndarray | None
    intrinsics: CameraIntrinsics
    camera_to_world: Pose
    detections: tuple[Detection, ...] | None = None
    """Detections recorded with the frame (a bag's); None: the replay's detector finds them."""


class ReplaySource(ABC):
    """A named sequence of frames; ``frames(indices)`` yields them in order.

    Subclasses set ``name``, ``frame_rate`` (frames per second of the recording, which sets the
    stamps and the tracker's buffer) and ``default_frames`` (how many frames a replay takes when
    not told: enough to show anchoring at work within about a minute on one CPU core).
    """

    name: ClassVar[str]
    frame_rate: ClassVar[float]
    default_frames: ClassVar[int]

    @property
    @abstractmethod
    def description(self) -> str:
        """One or two sentences: what the data is and where depth and pose come from."""

    @property
    @abstractmethod
    def frame_count(self) -> int:
        """How many frames the source holds."""

    @abstractmethod
    def frames(self, indices: Sequence[int]) -> Iterator[ReplayFrame]:
        """Yield the frames numbered ``indices`` (increasing), in that order."""

    def depth_for(self, frame: ReplayFrame, detections: Sequence[Detection]) -> np.ndarray:
        """The depth image the percepts of ``frame`` are measured on; RGB-D sources return their own."""
        if frame.depth_metres is None:
            raise InvalidInputError(f"frame {frame.index} of '{self.name}' has no depth and its source derives none")
        return frame.depth_metres

    def percept_config(self) -> PerceptGeneratorConfig:
        """The percept generator's thresholds suited to this source's range (default: the node's)."""
        return PerceptGeneratorConfig()

    def anchoring_overrides(self) -> dict[str, Any]:
        """Anchoring parameters (by their names in config/anchoring.yaml) this source's camera
        needs changed from the deployed ones; none by default."""
        return {}

    def anchoring_settings(
        self,
        *parameter_files: str | os.PathLike[str] | Mapping[str, Any],
        overrides: Mapping[str, Any] | None = None,
        node: str = "/anchoring",
    ) -> AnchoringSettings:
        """The settings the anchoring node ``node`` would run with, from ``parameter_files`` (files
        and inline values, as a launch file hands them; config/anchoring.yaml when none are given),
        offline (no knowledge base, no state on disk), with :meth:`anchoring_overrides`, then
        ``overrides``."""
        files = parameter_files or (config_file("anchoring.yaml"),)
        return load_anchoring_settings(
            *files, overrides={**OFFLINE_OVERRIDES, **self.anchoring_overrides(), **(overrides or {})}, node=node)

    def settings(self) -> dict[str, Any]:
        """The source's parameters, for the report."""
        return {}


def frame_indices(frame_count: int, first: int, count: int | None, stride: int) -> list[int]:
    """The source frames a replay visits: from ``first``, every ``stride``-th, at most ``count``."""
    if stride < 1:
        raise ConfigurationError(f"--stride must be at least 1, got {stride}")
    if first < 0:
        raise ConfigurationError(f"--first must not be negative, got {first}")
    if count is not None and count < 1:
        raise ConfigurationError(f"--frames must be at least 1, got {count}")
    if first >= frame_count:
        raise ConfigurationError(f"--first {first} is past the source's last frame ({frame_count - 1})")
    indices = list(range(first, frame_count, stride))
    return indices if count is None else indices[:count]
