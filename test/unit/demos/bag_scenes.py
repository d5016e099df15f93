"""Bags of a small scripted scene, written the way a robot's recorder writes them (CDR from rclpy
through the project's BagWriter), for the bag replay tests."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from geometry_msgs.msg import PoseStamped, TransformStamped
from rclpy.serialization import serialize_message
from std_msgs.msg import Header

from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor.ros.bags import BagWriter
from merlin2_sailor.ros.conversions import array_to_image, camera_info_message, detections_to_message, pose_to_message
from merlin2_sailor.ros.conversions.sensors import seconds_to_stamp

WIDTH, HEIGHT, RATE = 96, 64, 10.0
#: The optical frame of a level camera 1 m up looking along the world's x axis.
LEVEL_OPTICAL = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
TOPICS = {"color": "/camera/color/image_raw", "depth": "/camera/depth/image_raw",
          "info": "/camera/color/camera_info", "pose": "/camera/camera_pose", "detections": "/camera/detections"}


@dataclass(frozen=True)
class Scene:
    """``frames`` frames of a still camera 1 m up: a block 2 m away on the left (a cup on it),
    a wall 3 m away (a book on it). ``shuffle`` lists each frame's detections in a random order."""

    frames: int = 6
    shuffle: bool = False
    color_encoding: str = "rgb8"
    depth_encoding: str = "32FC1"
    pose: str = "PoseStamped"  # or "tf"
    with_detections: bool = True

    def camera_pose(self) -> Pose:
        return Pose(LEVEL_OPTICAL, np.array([0.0, 0.0, 1.0]))

    def color(self) -> np.ndarray:
        return np.random.default_rng(0).integers(0, 255, (HEIGHT, WIDTH, 3), dtype=np.uint8)

    def depth(self) -> np.ndarray:
        depth = np.full((HEIGHT, WIDTH), 3.0, dtype=np.float32)
        depth[10:40, 5:45] = 2.0
        return depth

    def detections(self, index: int) -> list[Detection]:
        found = [Detection(47, "cup", 0.9, BoundingBox2D.from_corners(10 + index % 2, 15, 30, 35)),
                 Detection(47, "cup", 0.85, BoundingBox2D.from_corners(32, 15, 44, 35)),
                 Detection(84, "book", 0.8, BoundingBox2D.from_corners(55, 10, 75, 30))]
        if self.shuffle:
            np.random.default_rng(index).shuffle(found)
        return found


def write_bag(path: Path, scene: Scene = Scene(), storage: str = "mcap") -> Path:
    """Write ``scene`` as the simulated house's topics; returns the bag's folder."""
    writer = BagWriter(path, storage)
    color, depth = scene.color(), scene.depth()
    if scene.color_encoding == "mono8":
        color = color[:, :, 0].copy()
    if scene.depth_encoding == "16UC1":
        depth = (depth * 1000).astype(np.uint16)
    types = {"color": "sensor_msgs/msg/Image", "depth": "sensor_msgs/msg/Image", "info": "sensor_msgs/msg/CameraInfo",
             "pose": "geometry_msgs/msg/PoseStamped", "detections": "merlin2_sailor_interfaces/msg/DetectionArray"}
    for key, topic in TOPICS.items():
        if (key == "pose" and scene.pose != "PoseStamped") or (key == "detections" and not scene.with_detections):
            continue
        writer.add_topic(topic, types[key])
    if scene.pose == "tf":
        from tf2_msgs.msg import TFMessage  # with tf2 only (SAILOR_UPSTREAM here)

        writer.add_topic("/tf", "tf2_msgs/msg/TFMessage")
        writer.add_topic("/tf_static", "tf2_msgs/msg/TFMessage")
        writer.write("/tf_static", 1, serialize_message(TFMessage(transforms=[
            _transform("base_link", "camera_optical", Pose(LEVEL_OPTICAL, np.array([0.0, 0.0, 1.0])), 0.0)])))
    for index in range(scene.frames):
        stamp = 100.0 + index / RATE
        header = Header(stamp=seconds_to_stamp(stamp), frame_id="camera_optical")
        recorded = int(stamp * 1e9)
        writer.write(TOPICS["info"], recorded, serialize_message(
            camera_info_message(WIDTH, HEIGHT, 80.0, 80.0, (WIDTH - 1) / 2, (HEIGHT - 1) / 2, header)))
        writer.write(TOPICS["color"], recorded, serialize_message(array_to_image(color, scene.color_encoding, header)))
        writer.write(TOPICS["depth"], recorded + 1, serialize_message(array_to_image(depth, scene.depth_encoding,
                                                                                     header)))
        if scene.pose == "PoseStamped":
            pose = PoseStamped(header=Header(stamp=header.stamp, frame_id="map"),
                               pose=pose_to_message(scene.camera_pose()))
            writer.write(TOPICS["pose"], recorded, serialize_message(pose))
        else:
            from tf2_msgs.msg import TFMessage

            writer.write("/tf", recorded, serialize_message(TFMessage(transforms=[
                _transform("map", "base_link", Pose(np.eye(3), np.zeros(3)), stamp)])))
        if scene.with_detections:
            writer.write(TOPICS["detections"], recorded + 2,
                         serialize_message(detections_to_message(scene.detections(index), header)))
    writer.close()
    return path


def _transform(parent: str, child: str, pose: Pose, stamp: float) -> TransformStamped:
    message = TransformStamped()
    message.header = Header(stamp=seconds_to_stamp(stamp), frame_id=parent)
    message.child_frame_id = child
    pose_message = pose_to_message(pose)
    message.transform.translation.x = pose_message.position.x
    message.transform.translation.y = pose_message.position.y
    message.transform.translation.z = pose_message.position.z
    message.transform.rotation = pose_message.orientation
    return message
