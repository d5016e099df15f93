"""The ``vtest`` replay: OpenCV's pedestrian video, monocular, with depth from the ground plane.

Debian's ``opencv-doc`` ships ``examples/data/vtest.avi``: 795 frames (768x576, 10 frames per
second) from a fixed camera on a building, looking down at people walking across a campus
road and lawn. There is no depth and no calibration, so depth comes from a ground-plane model
(:mod:`.ground_plane`): the camera stands ``camera_height`` metres above flat ground, pitched
``camera_pitch`` degrees down, with a ``field_of_view``-degree horizontal field of view; each
detection stands as an upright board on the ground at the bottom centre of its box.

The defaults (8 m, 34 degrees, 60 degrees) were chosen so that the ground-plane distance of the
pedestrians' foot points agrees with the distance their box heights give for people about
1.75 m tall, at the near, middle and far side of the road (within about 5 %): an estimate, not
a calibration. They are options of ``sailor replay vtest`` (``--camera-height``,
``--camera-pitch``, ``--field-of-view``); the replay reports the pedestrians' median measured
height, a check of the three.

The camera does not move, so its pose is constant: at (0, 0, camera_height), heading along x.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from merlin2_sailor.errors import ConfigurationError, InvalidInputError
from merlin2_sailor.perception.box3d import Box3DConfig
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor.perception.percept_generator import PerceptGeneratorConfig
from merlin2_sailor_demos.replay.debian_data import DebianData, locate
from merlin2_sailor_demos.replay.ground_plane import GroundPlaneCamera, ground_depth, standing_depth
from merlin2_sailor_demos.replay.source import ReplayFrame, ReplaySource

VTEST = DebianData(
    package="opencv-doc",
    member="usr/share/doc/opencv-doc/examples/data/vtest.avi",
    purpose="the 'vtest' replay",
)
DEFAULT_CAMERA_HEIGHT = 8.0  # metres
DEFAULT_CAMERA_PITCH = 34.0  # degrees below the horizon
DEFAULT_FIELD_OF_VIEW = 60.0  # degrees, horizontal
#: A board stands upright, so its optical depth changes by up to height * sin(pitch) from foot to
#: head (about 1 m here); the 3D box keeps the whole board instead of the node's 0.2 m band.
BOARD_DEPTH_BAND = 1.5


@dataclass(frozen=True, slots=True)
class VtestConfig:
    """``data``: the path of vtest.avi (empty: find or fetch the Debian package); the camera model's
    ``camera_height`` (m), ``camera_pitch`` (degrees down) and ``field_of_view`` (degrees, horizontal)."""

    data: str = ""
    camera_height: float = DEFAULT_CAMERA_HEIGHT
    camera_pitch: float = DEFAULT_CAMERA_PITCH
    field_of_view: float = DEFAULT_FIELD_OF_VIEW
    ground: GroundPlaneCamera = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "ground", GroundPlaneCamera(self.camera_height, self.camera_pitch,
                                                             self.field_of_view))


class VtestSource(ReplaySource):
    name = "vtest"
    frame_rate = 10.0
    default_frames = 500
    config_class = VtestConfig

    def __init__(self, config: VtestConfig | None = None) -> None:
        self.config = config or VtestConfig()
        self.path = Path(self.config.data).expanduser() if self.config.data else locate(VTEST)
        if not self.path.is_file():
            raise ConfigurationError(f"{self.path} is not a file; pass the path of vtest.avi with --data")
        capture = self._open()
        self._frame_count = int(capture.get(cv2.CAP_PROP_FRAME_COUNT))
        width, height = int(capture.get(cv2.CAP_PROP_FRAME_WIDTH)), int(capture.get(cv2.CAP_PROP_FRAME_HEIGHT))
        capture.release()
        if self._frame_count < 1 or width < 1 or height < 1:
            raise InvalidInputError(f"OpenCV reads no frames from {self.path}")
        ground = self.config.ground
        self.intrinsics = ground.intrinsics(width, height)
        self.camera_to_world = ground.camera_to_world()
        self._ground_depth = ground_depth(ground, self.intrinsics, self.camera_to_world)

    @property
    def description(self) -> str:
        ground = self.config.ground
        return (
            f"OpenCV vtest.avi (Debian opencv-doc): {self.frame_count} real frames of pedestrians from a fixed "
            f"camera, monocular; depth from a ground-plane model (camera {ground.height:g} m high, pitched "
            f"{ground.pitch_degrees:g} degrees down, {ground.horizontal_field_of_view_degrees:g} degrees horizontal "
            "field of view), each detection an upright board on its foot point"
        )

    @property
    def frame_count(self) -> int:
        return self._frame_count

    def frames(self, indices: Sequence[int]) -> Iterator[ReplayFrame]:
        capture = self._open()
        try:
            position = indices[0] if indices else 0
            capture.set(cv2.CAP_PROP_POS_FRAMES, position)
            for index in indices:
                while position < index:  # skip the frames the stride passes over
                    capture.grab()
                    position += 1
                ok, image = capture.read()
                position += 1
                if not ok:
                    return  # the container announced more frames than it holds
                color = cv2.cvtColor(image, cv2.COLOR_BGR2RGB)
                yield ReplayFrame(index, index / self.frame_rate, color, None, self.intrinsics, self.camera_to_world)
        finally:
            capture.release()

    def depth_for(self, frame: ReplayFrame, detections: Sequence[Detection]) -> np.ndarray:
        return standing_depth([detection.box for detection in detections], self._ground_depth, self.config.ground,
                              frame.intrinsics, frame.camera_to_world)

    def percept_config(self) -> PerceptGeneratorConfig:
        far = self.config.ground.maximum_range
        return PerceptGeneratorConfig(box3d=Box3DConfig(depth_band_half_width=BOARD_DEPTH_BAND, maximum_depth=far))

    def anchoring_overrides(self) -> dict[str, Any]:
        # Everyone in the picture is tens of metres away: the whole view counts for visibility.
        return {"visible_near": 1.0, "visible_range": self.config.ground.maximum_range, "visible_margin": 10.0}

    def settings(self) -> dict[str, Any]:
        ground = self.config.ground
        return {"data": str(self.path), "camera_height_m": ground.height, "camera_pitch_degrees": ground.pitch_degrees,
                "horizontal_field_of_view_degrees": ground.horizontal_field_of_view_degrees,
                "focal_length_px": round(self.intrinsics.fx, 1),
                "vertical_field_of_view_degrees": round(math.degrees(
                    2 * math.atan(self.intrinsics.height / 2 / self.intrinsics.fy)), 1)}

    def _open(self) -> cv2.VideoCapture:
        capture = cv2.VideoCapture(str(self.path))
        if not capture.isOpened():
            raise InvalidInputError(f"OpenCV cannot open the video {self.path}")
        return capture
