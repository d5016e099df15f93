"""rgbd_player publishes registered colour, metric depth, intrinsics and the camera pose."""

from __future__ import annotations

import numpy as np
import pytest
from geometry_msgs.msg import PoseStamped
from scipy.spatial.transform import Rotation
from sensor_msgs.msg import CameraInfo, Image

from merlin2_sailor.ros.conversions import depth_to_metres, image_to_array
from merlin2_sailor.ros.qos import SENSOR_DATA
from merlin2_sailor_demos.rgbd_player_node import DEFAULT_CAMERA_POSE

pytestmark = pytest.mark.ros


@pytest.mark.parametrize("depth_encoding", ["32FC1", "16UC1"])
def test_frames_and_pose_arrive_with_one_stamp_and_true_depth(depth_encoding, ros_probe, node_process) -> None:
    process = node_process("rgbd_player", "--ros-args", "-r", "__ns:=/cam",
                           "-p", f"depth_encoding:={depth_encoding}", "-p", "rate_hz:=20.0")
    try:
        assert ros_probe.wait_for_node("/cam/rgbd_player"), process.text
        colors = ros_probe.collect(Image, "/cam/color/image_raw", 2, SENSOR_DATA)
        depths = ros_probe.collect(Image, "/cam/depth/image_raw", 2, SENSOR_DATA)
        infos = ros_probe.collect(CameraInfo, "/cam/color/camera_info", 1, SENSOR_DATA)
        poses = ros_probe.collect(PoseStamped, "/cam/camera_pose", 1, SENSOR_DATA)
    finally:
        assert process.stop() == 0, process.text
    assert colors and depths and infos and poses, process.text
    color, depth = image_to_array(colors[0]), image_to_array(depths[0])
    assert color.shape == (500, 741, 3) and colors[0].encoding == "rgb8"
    assert depths[0].encoding == depth_encoding and depth.shape == (500, 741)
    metres = depth_to_metres(depth, depth_encoding)
    assert 2.2 < np.nanmedian(metres[200:300, 250:450]) < 3.0
    assert infos[0].k[0] == pytest.approx(994.978) and infos[0].width == 741
    assert colors[0].header.frame_id == "camera_color_optical_frame"
    assert poses[0].header.frame_id == "map"


def test_default_pose_looks_along_world_x_from_one_metre_up() -> None:
    rotation = Rotation.from_quat(DEFAULT_CAMERA_POSE[3:])
    np.testing.assert_allclose(rotation.apply([0.0, 0.0, 1.0]), [1.0, 0.0, 0.0], atol=1e-9)  # optical z
    np.testing.assert_allclose(rotation.apply([1.0, 0.0, 0.0]), [0.0, -1.0, 0.0], atol=1e-9)  # right
    np.testing.assert_allclose(rotation.apply([0.0, 1.0, 0.0]), [0.0, 0.0, -1.0], atol=1e-9)  # down
    assert DEFAULT_CAMERA_POSE[2] == 1.0


def test_invalid_parameters_stop_the_node_with_a_clear_message(node_process) -> None:
    process = node_process("rgbd_player", "--ros-args", "-p", "depth_encoding:=rgb8")
    process.process.wait(timeout=30.0)  # it must exit by itself
    assert process.stop() == 2
    assert "depth_encoding must be 32FC1 or 16UC1" in process.text
    assert "Traceback" not in process.text
