"""The ``sr300`` replay: ViSP's real Intel SR300 RGB-D sequence of a model castle.

Debian's ``visp-images-data`` holds, under ``ViSP-images/mbt-depth/castel``, 30 frames a
hand-held SR300 recorded of a model castle on a desk (with a paper box, scissors and a pen pot
beside it): ``castel/image_NNNN.pgm`` (640x480 grey, the colour camera; ``.png`` in newer
releases) and ``castel/depth_image_NNNN.bin`` (640x480 raw depth, see :mod:`.visp_files`).
Beside them: ``chateau.xml`` (the colour camera's intrinsics), ``chateau_depth.xml`` (the depth
camera's) and ``depth_M_color.txt`` (the colour-to-depth transform).

What the files do not say, taken from ViSP's own reader of this sequence (its
``mbtGenericTrackingDepth`` example, which states the values are for the SR300): one raw depth
unit is 0.000124986647 m, and the depth camera's lens follows the inverse Brown-Conrady model
with coefficients (0.165056542, -0.0508309528, 0.00435937941, 0.00541406544, 0.250085592).

Depth is registered to the grey image (:mod:`.depth_registration`), which the detector sees as
RGB with three equal channels. The sequence has no camera poses, so they are estimated by RGB-D
visual odometry (:mod:`.visual_odometry`); the world frame is the first camera's, turned so
that z is up (x forward, y left). The files carry no stamps: a nominal 10 Hz is used.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import ConfigurationError, InvalidInputError
from merlin2_sailor_demos.replay.debian_data import DebianData, locate
from merlin2_sailor_demos.replay.depth_registration import DepthCamera, register_depth
from merlin2_sailor_demos.replay.source import WORLD_FROM_LEVEL_OPTICAL, ReplayFrame, ReplaySource
from merlin2_sailor_demos.replay.visp_files import read_camera_parameters, read_homogeneous_matrix, read_raw_depth
from merlin2_sailor_demos.replay.visual_odometry import VisualOdometry

CASTEL = DebianData(
    package="visp-images-data",
    member="usr/share/visp-images-data/ViSP-images/mbt-depth/castel",
    purpose="the 'sr300' replay",
)
SR300_METRES_PER_DEPTH_UNIT = 0.000124986647
SR300_DEPTH_DISTORTION = (0.165056542, -0.0508309528, 0.00435937941, 0.00541406544, 0.250085592)
IMAGE_EXTENSIONS = (".pgm", ".png")


@dataclass(frozen=True, slots=True)
class Sr300Config:
    """``data``: the ``castel`` folder (holding chateau.xml); empty: find or fetch the Debian package.
    ``odometry``: estimate the camera's motion; off, the camera is taken as still."""

    data: str = ""
    odometry: bool = True


class Sr300CastelSource(ReplaySource):
    name = "sr300"
    frame_rate = 10.0
    default_frames = 30
    config_class = Sr300Config

    def __init__(self, config: Sr300Config | None = None) -> None:
        self.config = config or Sr300Config()
        folder = Path(self.config.data).expanduser() if self.config.data else locate(CASTEL)
        if not (folder / "chateau.xml").is_file() and (folder / "mbt-depth" / "castel").is_dir():
            folder = folder / "mbt-depth" / "castel"  # --data may name the ViSP-images folder
        if not (folder / "chateau.xml").is_file():
            raise ConfigurationError(
                f"{folder} is not ViSP's castel folder (no chateau.xml); pass the folder "
                ".../ViSP-images/mbt-depth/castel with --data"
            )
        self.folder = folder
        self._images = sorted(
            path for path in (folder / "castel").glob("image_*") if path.suffix in IMAGE_EXTENSIONS
        )
        if not self._images:
            raise ConfigurationError(f"{folder / 'castel'} holds no image_NNNN.pgm frames")
        color = read_camera_parameters(folder / "chateau.xml")
        depth = read_camera_parameters(folder / "chateau_depth.xml")
        depth_from_color = read_homogeneous_matrix(folder / "depth_M_color.txt")
        self.color_from_depth = depth_from_color.inverse()
        self.depth_camera = DepthCamera(depth.fx, depth.fy, depth.cx, depth.cy, SR300_METRES_PER_DEPTH_UNIT,
                                        SR300_DEPTH_DISTORTION)
        height, width = self._read_grey(0).shape
        self.intrinsics = CameraIntrinsics(color.fx, color.fy, color.cx, color.cy, width, height)
        self.lost_steps = 0  # odometry steps of the latest pass that found too few matches

    @property
    def description(self) -> str:
        return (
            f"ViSP 'castel' (Debian visp-images-data): {self.frame_count} real frames of a hand-held Intel SR300 "
            "around a model castle on a desk; grey image, depth registered to it, camera motion from RGB-D "
            "visual odometry" + ("" if self.config.odometry else " (off: camera taken as still)")
        )

    @property
    def frame_count(self) -> int:
        return len(self._images)

    def frames(self, indices: Sequence[int]) -> Iterator[ReplayFrame]:
        odometry = VisualOdometry(self.intrinsics)
        camera_to_world = Pose(WORLD_FROM_LEVEL_OPTICAL, np.zeros(3))
        self.lost_steps = 0
        for index in indices:
            grey = self._read_grey(index)
            depth = register_depth(self._read_depth(index), self.depth_camera, self.color_from_depth, self.intrinsics)
            if self.config.odometry:
                step = odometry.step(grey, depth)
                camera_to_world = camera_to_world @ step.current_from_previous.inverse()
                self.lost_steps += int(step.lost)
            color = np.repeat(grey[:, :, np.newaxis], 3, axis=2)
            yield ReplayFrame(index, index / self.frame_rate, color, depth, self.intrinsics, camera_to_world)

    def settings(self) -> dict[str, Any]:
        return {"data": str(self.folder), "odometry": self.config.odometry,
                "metres_per_depth_unit": SR300_METRES_PER_DEPTH_UNIT}

    def _read_grey(self, index: int) -> np.ndarray:
        path = self._images[index]
        grey = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE)
        if grey is None:
            raise InvalidInputError(f"cannot read the image {path}")
        return grey

    def _read_depth(self, index: int) -> np.ndarray:
        image = self._images[index]
        number = image.stem.removeprefix("image_")
        return read_raw_depth(image.parent / f"depth_image_{number}.bin")
