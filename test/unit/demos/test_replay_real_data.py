"""The real data behind the replays: ViSP's SR300 castle, OpenCV's vtest video, the motorcycle views.

The Debian data is fetched into the cache the way ``sailor replay`` does it (``apt-get
download``, only the needed part unpacked) when it is not there yet; where that is impossible
(no apt-get, no network) the test is skipped with the reason the replay would print.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from merlin2_sailor.errors import DependencyError
from merlin2_sailor_demos.replay.motorcycle import MotorcycleConfig, MotorcycleSource
from merlin2_sailor_demos.replay.source import ReplaySource
from merlin2_sailor_demos.replay.sources import create_source


def real_source(name: str) -> ReplaySource:
    try:
        return create_source(name)
    except DependencyError as error:
        pytest.skip(f"the '{name}' data cannot be had here: {error}")


def test_the_sr300_castle_frames_come_with_both_cameras_and_registered_depth() -> None:
    source = real_source("sr300")
    assert source.frame_count == 30
    intrinsics = source.intrinsics
    assert (intrinsics.fx, intrinsics.cx, intrinsics.width, intrinsics.height) == pytest.approx(
        (615.1674804688, 312.1889953613, 640, 480))
    assert source.depth_camera.fx == pytest.approx(476.0536193848)
    assert source.color_from_depth.translation == pytest.approx([0.0247, -0.0008, 0.0037], abs=5e-4)
    frames = list(source.frames(range(0, 30, 3)))
    first = frames[0]
    assert first.color.shape == (480, 640, 3) and (first.color[..., 0] == first.color[..., 2]).all()
    depth = first.depth_metres
    assert 0.6 < np.isfinite(depth).mean() < 0.9
    assert 0.2 < np.nanmedian(depth) < 0.35  # the castle is about 30 cm from the camera
    # The hand-held camera moves a few centimetres and degrees; odometry follows every step.
    assert source.lost_steps == 0
    travelled = np.linalg.norm(frames[-1].camera_to_world.translation - first.camera_to_world.translation)
    assert 0.005 < travelled < 0.1


def test_the_vtest_video_has_795_frames_and_a_ground_that_recedes_upwards() -> None:
    source = real_source("vtest")
    assert source.frame_count == 795
    frames = list(source.frames([0, 10]))
    assert [frame.index for frame in frames] == [0, 10] and frames[1].stamp == pytest.approx(1.0)
    assert frames[0].color.shape == (576, 768, 3) and frames[0].depth_metres is None
    depth = source.depth_for(frames[0], [])
    assert np.isfinite(depth).all()  # the whole view is below the horizon
    assert 8.0 < depth[-1, 384] < depth[288, 384] < depth[0, 384] < 60.0
    # The optical axis' ray meets the ground height / sin(pitch) away.
    assert depth[287:289, 383:385].mean() == pytest.approx(8.0 / math.sin(math.radians(34.0)), rel=1e-3)


def test_the_motorcycle_sequence_starts_at_the_real_frame_and_slides_back_and_forth() -> None:
    pytest.importorskip("skimage.data", reason="the motorcycle source needs scikit-image (pip install scikit-image)")
    source = MotorcycleSource(MotorcycleConfig(views=8))
    frames = list(source.frames(range(8)))
    from merlin2_sailor_demos.rgbd_sources import motorcycle_frames

    (real,) = motorcycle_frames()
    assert np.array_equal(frames[0].color, real.color)
    shifts = [source.shift_of(index) for index in range(8)]
    assert shifts[2] == pytest.approx(0.0965) and shifts[6] == pytest.approx(-0.0965)
    offsets = [frame.camera_to_world.translation[1] for frame in frames]
    assert offsets[2] == pytest.approx(-0.0965)  # to the camera's right is -y in the world
    # Moved 9.65 cm right, the motorcycle (about 2.5 m away) slides about 38 px left.
    row = 300
    assert np.isfinite(frames[2].depth_metres[row]).mean() > 0.8  # most depth is measured, not filled
    expected = real.fx * 0.0965 / np.nanmedian(real.depth_metres[row, 300:400])
    best = min(range(20, 60), key=lambda shift: np.nanmean(np.abs(
        frames[2].color[row, 200:500].astype(int) - real.color[row, 200 + shift:500 + shift].astype(int))))
    assert abs(best - expected) <= 3
