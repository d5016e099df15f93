"""The detector and percept_generator nodes as real processes over DDS.

Real frames come from rgbd_player (Middlebury's Motorcycle, true metric depth). The moving-camera
and bad-input tests publish a synthetic scene from the test's own probe node instead: a flat
plate of known world position in front of a wall, rendered by ray casting from camera poses the
test chooses, with the plate's exact pixel box as an external detection. Its geometry is known in
closed form, so a percept that drifts with the camera, or that comes out in the camera frame,
fails the test.
"""

from __future__ import annotations

import importlib.util
import math
import sys
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import Odometry
from scipy.spatial.transform import Rotation
from sensor_msgs.msg import CameraInfo, Image, PointCloud2
from std_msgs.msg import Header
from visualization_msgs.msg import Marker, MarkerArray

from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor.ros.conversions import (
    array_to_image,
    array_to_point_cloud,
    camera_info_message,
    detection_to_message,
    detections_from_message,
    percepts_from_message,
    pose_to_message,
    seconds_to_stamp,
    stamp_to_seconds,
)
from merlin2_sailor.ros.newest_frame_mailbox import NewestFrameMailbox
from merlin2_sailor.ros.qos import SENSOR_DATA
from merlin2_sailor_demos.rgbd_sources import load_source
from merlin2_sailor_interfaces.msg import DetectionArray, PerceptArray

pytestmark = pytest.mark.ros

# --- a synthetic scene with known geometry -----------------------------------------------------

WIDTH, HEIGHT, FOCAL = 320, 240, 240.0
CX, CY = (WIDTH - 1) / 2.0, (HEIGHT - 1) / 2.0
PLATE_CENTRE = np.array([3.0, 0.0, 1.0])  # world frame (x forward, y left, z up), metres
PLATE_HALF_SIZE = 0.2  # along world y and z; the plate lies in the plane x = 3
WALL_X = 5.0
#: Optical frame (z forward, x right, y down) into a z-up world looking along +x.
OPTICAL_TO_FORWARD = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
#: Static pose of the optical frame in the robot base, as the Odometry variant's extrinsics.
CAMERA_EXTRINSICS = [0.1, 0.0, 0.4, -0.5, 0.5, -0.5, 0.5]


@dataclass(frozen=True)
class SyntheticFrame:
    color: np.ndarray  # (H, W, 3) uint8
    depth: np.ndarray  # (H, W) float32 metres along the optical axis
    points: np.ndarray  # (H, W, 3) float32, optical frame
    plate_box: BoundingBox2D  # the plate's exact pixel extent (edge coordinates)


def camera_pose(position: tuple[float, float, float], yaw_degrees: float) -> Pose:
    yaw = Rotation.from_euler("z", yaw_degrees, degrees=True).as_matrix()
    return Pose(yaw @ OPTICAL_TO_FORWARD, position)


def render(camera_to_world: Pose) -> SyntheticFrame:
    """Ray-cast the plate and the wall; depth is the optical z of each pixel's first hit."""
    columns, rows = np.meshgrid(np.arange(WIDTH), np.arange(HEIGHT))
    rays_camera = np.stack([(columns - CX) / FOCAL, (rows - CY) / FOCAL, np.ones((HEIGHT, WIDTH))], axis=-1)
    rays_world = rays_camera @ camera_to_world.rotation.T
    origin = camera_to_world.translation
    plate_distance = (PLATE_CENTRE[0] - origin[0]) / rays_world[..., 0]  # optical z, since ray z is 1
    hits = origin + plate_distance[..., np.newaxis] * rays_world
    on_plate = (np.abs(hits[..., 1:] - PLATE_CENTRE[1:]) <= PLATE_HALF_SIZE).all(axis=-1) & (plate_distance > 0)
    depth = np.where(on_plate, plate_distance, (WALL_X - origin[0]) / rays_world[..., 0]).astype(np.float32)
    color = np.where(on_plate[..., np.newaxis], [200, 30, 30], [128, 128, 128]).astype(np.uint8)
    plate_rows, plate_columns = np.nonzero(on_plate)
    box = BoundingBox2D.from_corners(plate_columns.min(), plate_rows.min(), plate_columns.max() + 1.0,
                                     plate_rows.max() + 1.0)
    points = (rays_camera * depth[..., np.newaxis]).astype(np.float32)
    return SyntheticFrame(color, depth, points, box)


class SceneCamera:
    """Publishes a synthetic camera's topics from the probe node, as a driver plus odometry would."""

    def __init__(self, probe: Any, namespace: str, depth_source: str = "depth_image",
                 pose_message: str = "PoseStamped", detections_topic: str = "detections",
                 detections_type: Any = DetectionArray) -> None:
        node, self._probe = probe.node, probe
        self._depth_source, self._pose_message = depth_source, pose_message
        self.image = node.create_publisher(Image, f"{namespace}/color/image_raw", SENSOR_DATA)
        self.info = node.create_publisher(CameraInfo, f"{namespace}/color/camera_info", SENSOR_DATA)
        self.depth = (node.create_publisher(Image, f"{namespace}/depth/image_raw", SENSOR_DATA)
                      if depth_source == "depth_image"
                      else node.create_publisher(PointCloud2, f"{namespace}/depth/points", SENSOR_DATA))
        self.pose = (node.create_publisher(PoseStamped, f"{namespace}/camera_pose", SENSOR_DATA)
                     if pose_message == "PoseStamped"
                     else node.create_publisher(Odometry, f"{namespace}/odom", SENSOR_DATA))
        self.detections = node.create_publisher(detections_type, f"{namespace}/{detections_topic}", SENSOR_DATA)

    def wait_until_connected(self) -> bool:
        publishers = (self.image, self.info, self.depth, self.pose, self.detections)
        connected = self._probe.wait_for(lambda: all(p.get_subscription_count() > 0 for p in publishers))
        time.sleep(0.5)  # let the nodes' own connections (detector -> percept_generator) settle too
        return connected

    def publish(self, stamp: float, camera_to_world: Pose, frame: SyntheticFrame,
                detections: list[Any] | None = None, detections_message: Any = None, **overrides: Any) -> None:
        """Publish one frame; ``overrides`` replaces a message by topic name (info, image, depth, pose),
        ``detections_message`` the detections (another detector's type, its header set here)."""
        header = Header(stamp=seconds_to_stamp(stamp), frame_id="camera_color_optical_frame")
        if detections is None:
            detections = [detection_to_message(Detection(0, "plate", 0.9, frame.plate_box))]
        messages = {
            "info": camera_info_message(WIDTH, HEIGHT, FOCAL, FOCAL, CX, CY, header),
            "image": array_to_image(frame.color, "rgb8", header),
            "depth": (array_to_image(frame.depth, "32FC1", header) if self._depth_source == "depth_image"
                      else array_to_point_cloud(frame.points, header)),
            "pose": self._pose(header, camera_to_world),
            "detections": DetectionArray(header=header, detections=detections),
        }
        if detections_message is not None:
            detections_message.header = header
            messages["detections"] = detections_message
        messages.update(overrides)
        for name, message in messages.items():
            getattr(self, name).publish(message)

    def _pose(self, header: Header, camera_to_world: Pose) -> Any:
        world_header = Header(stamp=header.stamp, frame_id="map")
        if self._pose_message == "PoseStamped":
            return PoseStamped(header=world_header, pose=pose_to_message(camera_to_world))
        base_to_camera = Pose.from_quaternion(CAMERA_EXTRINSICS[3:], CAMERA_EXTRINSICS[:3])
        odometry = Odometry(header=world_header, child_frame_id="base_link")
        odometry.pose.pose = pose_to_message(camera_to_world.compose(base_to_camera.inverse()))
        return odometry


@pytest.fixture
def subscribe(ros_probe) -> Iterator[Callable[[Any, str], list[Any]]]:
    """Subscribe the probe to a topic for the whole test; returns the list messages arrive in."""
    with ros_probe.listener() as listener:
        def start(message_type: Any, topic: str) -> list[Any]:
            received: list[Any] = []
            listener.create_subscription(message_type, topic, received.append, SENSOR_DATA)
            return received

        yield start


def stamp_of(message: Any) -> float:
    return stamp_to_seconds(message.header.stamp)


# --- detector ---------------------------------------------------------------------------------


def test_detector_finds_the_motorcycle_with_the_image_stamp_and_survives_bad_images(
    ros_probe, node_process, subscribe
) -> None:
    images = subscribe(Image, "/cam/color/image_raw")
    detections = subscribe(DetectionArray, "/cam/detections")
    player = node_process("rgbd_player", "--ros-args", "-r", "__ns:=/cam")
    detector = node_process("detector", "--ros-args", "-r", "__ns:=/cam", "-p", "report_period:=1.0")

    def comparable() -> list[DetectionArray]:  # the probe may discover the player after the detector did
        return [array for array in detections if images and stamp_of(array) >= stamp_of(images[0])]

    assert ros_probe.wait_for(lambda: len(comparable()) >= 3), player.text + detector.text
    assert player.stop() == 0
    image_stamps = {stamp_of(image) for image in images}
    for array in comparable()[:3]:
        assert stamp_of(array) in image_stamps  # the image's own header, not the time of detection
        assert array.header.frame_id == "camera_color_optical_frame"
        found = detections_from_message(array)
        assert [d.class_name for d in found].count("motorcycle") == 1, [(d.class_name, d.score) for d in found]
        motorcycle = next(d for d in found if d.class_name == "motorcycle")
        assert motorcycle.score > 0.9
        np.testing.assert_allclose(motorcycle.box.corners, (102.6, 64.8, 679.8, 444.7), atol=15.0)

    # Bad images (a depth encoding, a truncated buffer) are logged and dropped; the next good one
    # is detected as usual. Spaced out so that none is replaced in the mailbox by its successor.
    frame = load_source("motorcycle")[0]
    publisher = ros_probe.node.create_publisher(Image, "/cam/color/image_raw", SENSOR_DATA)
    # Best effort does not resend: what a new publisher sends before discovery has matched it with
    # the detector's subscription (and the probe's own) is lost (CI, 4 December: the first bad image).
    assert ros_probe.wait_for(lambda: publisher.get_subscription_count() >= 2, timeout=10.0)
    truncated = array_to_image(frame.color, "rgb8")
    truncated.data = truncated.data[:1000]
    bad = [array_to_image(frame.depth_metres, "32FC1"), truncated]
    start = 1000.0
    for index, message in enumerate([*bad, array_to_image(frame.color, "rgb8")]):
        message.header = Header(stamp=seconds_to_stamp(start + index), frame_id="camera_color_optical_frame")
        publisher.publish(message)
        time.sleep(0.4)
    assert ros_probe.wait_for(lambda: any(stamp_of(array) == start + 2 for array in detections), timeout=10.0)
    assert not any(stamp_of(array) in (start, start + 1) for array in detections)
    assert detector.process.poll() is None, detector.text
    assert detector.stop() == 0
    assert "image dropped" in detector.text and "cannot be fed to a detector" in detector.text
    assert "ms/frame detecting" in detector.text and "Traceback" not in detector.text


def test_the_newest_frame_wins_and_replaced_frames_are_counted() -> None:
    mailbox = NewestFrameMailbox()
    for frame in ("first", "second", "third"):  # the worker is busy: nobody takes them
        mailbox.put(frame)
    assert mailbox.take() == "third" and mailbox.dropped == 2
    taken: list[Any] = []
    worker = threading.Thread(target=lambda: taken.append(mailbox.take()))
    worker.start()  # blocks: nothing is waiting
    mailbox.close()
    worker.join(timeout=5.0)
    assert not worker.is_alive() and taken == [None]


def test_a_mailbox_of_several_frames_catches_up_on_a_burst_and_lets_the_oldest_go() -> None:
    mailbox = NewestFrameMailbox(capacity=3)
    for frame in range(5):  # a burst: the worker is busy with an earlier frame
        mailbox.put(frame)
    assert mailbox.dropped == 2  # frames 0 and 1, the oldest, let go
    assert [mailbox.take() for _ in range(3)] == [2, 3, 4]  # the rest in the order they came
    with pytest.raises(ValueError, match="at least one frame"):
        NewestFrameMailbox(capacity=0)


# --- the perceptual chain -----------------------------------------------------------------------


def test_chain_publishes_the_motorcycle_percept_in_the_world_frame_with_a_stable_tracker_id(
    ros_probe, node_process, subscribe
) -> None:
    percept_arrays = subscribe(PerceptArray, "/cam/percepts")
    markers = subscribe(MarkerArray, "/cam/percept_markers")
    processes = [
        node_process("rgbd_player", "--ros-args", "-r", "__ns:=/cam"),
        node_process("detector", "--ros-args", "-r", "__ns:=/cam"),
        node_process("percept_generator", "--ros-args", "-r", "__ns:=/cam"),
    ]

    def tracked() -> list[PerceptArray]:
        return [array for array in percept_arrays if array.percepts and array.percepts[0].tracker_id]

    reached = ros_probe.wait_for(lambda: len(tracked()) >= 5, timeout=30.0)
    exit_codes = [process.stop() for process in processes]
    log = "".join(process.text for process in processes)
    assert reached, log
    assert exit_codes == [0, 0, 0], log

    for array in percept_arrays:
        assert array.header.frame_id == "map"
        (percept,) = percepts_from_message(array)
        assert percept.class_name == "motorcycle"
        assert percept.stamp == pytest.approx(stamp_of(array), abs=1e-6)
        # The camera is 1 m above the map origin looking along +x; the motorcycle is ~2.4 m ahead.
        assert percept.position[0] == pytest.approx(2.4, abs=0.3)
        assert abs(percept.position[1]) < 0.5 and 0.6 < percept.position[2] < 1.4, percept.position
        crop_height, crop_width = percept.crop.shape[:2]
        # The crop holds every pixel the fractional box touches: up to one more at each edge.
        assert 0 <= crop_height - percept.box.height < 2 and 0 <= crop_width - percept.box.width < 2
    ids = [array.percepts[0].tracker_id for array in tracked()]
    assert len(set(ids)) == 1, ids
    # Once confirmed, the track keeps its id on every later frame of the (static) scene.
    first_tracked = percept_arrays.index(tracked()[0])
    assert all(array.percepts[0].tracker_id == ids[0] for array in percept_arrays[first_tracked:])
    cubes = [marker for array in markers for marker in array.markers if marker.type == Marker.CUBE]
    assert cubes and all(cube.header.frame_id == "map" for cube in cubes)
    assert cubes[-1].pose.position.x == pytest.approx(2.4, abs=0.3)


@pytest.mark.parametrize(
    ("depth_source", "pose_message"), [("depth_image", "PoseStamped"), ("point_cloud", "Odometry")]
)
def test_percepts_stay_at_the_true_world_position_while_the_camera_moves(
    depth_source, pose_message, ros_probe, node_process, subscribe
) -> None:
    namespace = "/moving"
    percept_arrays = subscribe(PerceptArray, f"{namespace}/percepts")
    detector = node_process("detector", "--ros-args", "-r", f"__ns:={namespace}", "-p", "backend:=external")
    generator = node_process(
        "percept_generator", "--ros-args", "-r", f"__ns:={namespace}",
        "-p", f"depth_source:={depth_source}", "-p", f"pose_message:={pose_message}",
        "-p", f"camera_extrinsics:={CAMERA_EXTRINSICS}", "-p", "tracker_frame_rate:=10.0",
    )
    camera = SceneCamera(ros_probe, namespace, depth_source, pose_message, detections_topic="detections_in")
    assert camera.wait_until_connected(), detector.text + generator.text

    frame_count, start = 10, 2000.0
    poses = [camera_pose((0.05 * k, -0.3 + 0.06 * k, 0.9 + 0.02 * k), -6.0 + 1.2 * k) for k in range(frame_count)]
    invalid = detection_to_message(Detection(0, "ghost", 0.5, BoundingBox2D(10.0, 10.0, 5.0, 5.0)))
    invalid.score = math.nan  # the external detector must drop this one and keep the plate
    for k, pose in enumerate(poses):
        frame = render(pose)
        camera.publish(start + 0.1 * k, pose, frame,
                       detections=[detection_to_message(Detection(0, "plate", 0.9, frame.plate_box)), invalid])
        time.sleep(0.1)
    ros_probe.wait_for(lambda: any(stamp_of(a) == pytest.approx(start + 0.9) for a in percept_arrays), timeout=5.0)
    assert generator.stop() == 0 and detector.stop() == 0
    log = detector.text + generator.text

    assert len(percept_arrays) >= frame_count - 2, log  # best effort on loopback: rarely a loss
    camera_travel = np.linalg.norm(poses[-1].translation - poses[0].translation)
    assert camera_travel > 0.6
    for array in percept_arrays:
        assert array.header.frame_id == "map"
        (percept,) = percepts_from_message(array)
        assert percept.class_name == "plate"
        np.testing.assert_allclose(percept.position, PLATE_CENTRE, atol=0.02, err_msg=log)
    assert percept_arrays[-1].percepts[0].tracker_id  # tracked over the moving frames
    assert "external detection dropped" in detector.text and "Traceback" not in log


@pytest.mark.parametrize("detections_type", ["yolo_msgs", "vision_msgs"])
def test_percepts_from_a_robots_own_detector_message_type(
    detections_type, upstream_stack, ros_probe, node_process, subscribe
) -> None:
    """yolo_ros' and vision_msgs' detections, read directly: the same percepts as the project's type."""
    upstream_stack(f"{detections_type}.msg")
    sys.path.insert(0, str(Path(__file__).resolve().parent))  # test/ros is not a package: its helpers
    from detector_messages import vision_array, yolo_array

    namespace = f"/{detections_type}"
    percept_arrays = subscribe(PerceptArray, f"{namespace}/percepts")
    generator = node_process("percept_generator", "--ros-args", "-r", f"__ns:={namespace}",
                             "-p", f"detections_type:={detections_type}", "-p", "tracker_frame_rate:=10.0")
    to_message = yolo_array if detections_type == "yolo_msgs" else vision_array
    camera = SceneCamera(ros_probe, namespace, detections_type=type(to_message([])))
    assert camera.wait_until_connected(), generator.text

    start, pose = 3000.0, camera_pose((0.0, 0.0, 0.9), 0.0)
    frame = render(pose)
    for k in range(5):
        camera.publish(start + 0.1 * k, pose, frame,
                       detections_message=to_message([Detection(0, "plate", 0.9, frame.plate_box)]))
        time.sleep(0.1)
    ros_probe.wait_for(lambda: len(percept_arrays) >= 4, timeout=10.0)
    assert generator.stop() == 0
    assert len(percept_arrays) >= 4, generator.text
    assert f"detections as {detections_type}/msg/" in generator.text
    for array in percept_arrays:
        (percept,) = percepts_from_message(array)
        assert percept.class_name == "plate"
        np.testing.assert_allclose(percept.position, PLATE_CENTRE, atol=0.02, err_msg=generator.text)


# --- bad input ----------------------------------------------------------------------------------


def test_percept_generator_logs_bad_input_and_keeps_publishing(ros_probe, node_process, subscribe) -> None:
    namespace = "/bad"
    percept_arrays = subscribe(PerceptArray, f"{namespace}/percepts")
    generator = node_process("percept_generator", "--ros-args", "-r", f"__ns:={namespace}",
                             "-p", "tracker_frame_rate:=4.0")
    camera = SceneCamera(ros_probe, namespace)
    assert camera.wait_until_connected(), generator.text
    # The first frame's percepts are asserted too: the generator's publisher must be known first.
    assert ros_probe.wait_for(lambda: ros_probe.node.count_publishers(f"{namespace}/percepts") > 0), generator.text

    pose = camera_pose((0.0, 0.0, 1.0), 0.0)
    frame = render(pose)
    header = Header(frame_id="camera_color_optical_frame")
    nan_pose = PoseStamped(header=Header(frame_id="map"), pose=pose_to_message(pose))
    nan_pose.pose.position.y = math.nan
    plate = detection_to_message(Detection(0, "plate", 0.9, frame.plate_box))
    outside = detection_to_message(Detection(0, "plate", 0.9, BoundingBox2D(WIDTH + 50.0, 30.0, 20.0, 20.0)))
    bad_score = detection_to_message(Detection(0, "plate", 0.9, frame.plate_box))
    bad_score.score = math.nan
    steps: list[tuple[dict[str, Any], int | None]] = [  # (what replaces the good message, percepts expected)
        ({}, 1),
        ({"image": array_to_image(frame.depth, "32FC1", header)}, None),  # wrong colour encoding
        ({"depth": array_to_image(frame.color, "rgb8", header)}, None),  # wrong depth encoding
        ({"depth": array_to_image(frame.depth[:100, :120].copy(), "32FC1", header)}, None),  # size mismatch
        ({"detections": [plate, outside]}, 1),  # the box outside the image is dropped alone
        ({"depth": array_to_image(np.full((HEIGHT, WIDTH), np.nan, np.float32), "32FC1", header)}, 0),
        ({"pose": nan_pose}, None),
        ({"info": CameraInfo(header=header, width=WIDTH, height=HEIGHT)}, 1),  # keeps the last good K
        ({"detections": [bad_score]}, None),
        ({}, 1),
    ]
    start = 3000.0
    for index, (overrides, _) in enumerate(steps):
        stamp = start + 0.25 * index
        header.stamp = seconds_to_stamp(stamp)
        for message in overrides.values():
            if hasattr(message, "header"):
                message.header.stamp = header.stamp
        detections = overrides.pop("detections", None)
        camera.publish(stamp, pose, frame, detections=detections, **overrides)
        time.sleep(0.25)
    last_stamp = start + 0.25 * (len(steps) - 1)
    ros_probe.wait_for(lambda: any(stamp_of(array) == last_stamp for array in percept_arrays), timeout=5.0)
    alive = generator.process.poll() is None
    assert generator.stop() == 0
    assert alive, generator.text

    published = {round((stamp_of(array) - start) / 0.25): len(array.percepts) for array in percept_arrays}
    expected = {index: count for index, (_, count) in enumerate(steps) if count is not None}
    assert published == expected, generator.text
    for reason in ("image dropped", "depth dropped", "differ in size", "outside_image", "too_few_depth_pixels",
                   "pose dropped", "camera info dropped", "detections dropped"):
        assert reason in generator.text, f"{reason!r} not logged:\n{generator.text}"
    assert "Traceback" not in generator.text


# --- configuration errors -------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("executable", "parameter", "message"),
    [
        ("detector", "backend:=ultralytics", "needs the parameter 'weights'"),
        ("detector", "backend:=yolo", "backend must be one of external, ssd_mobilenet, ultralytics"),
        pytest.param("percept_generator", "pose_source:=tf", "tf2_ros, which is not installable from PyPI",
                     marks=pytest.mark.skipif(importlib.util.find_spec("tf2_ros") is not None,
                                              reason="tf2_ros is installed here (SAILOR_UPSTREAM): the TF tests "
                                                     "below run pose_source tf for real")),
        ("percept_generator", "detections_type:=darknet", "detections_type' must be one of"),
        pytest.param("percept_generator", "detections_type:=vision_msgs", "need the vision_msgs package",
                     marks=pytest.mark.skipif(importlib.util.find_spec("vision_msgs") is not None,
                                              reason="vision_msgs is installed here (SAILOR_UPSTREAM)")),
        ("percept_generator", "camera_extrinsics:=[1.0, 2.0]", "camera_extrinsics must be"),
    ],
)
def test_configuration_errors_stop_the_node_with_a_clear_message(executable, parameter, message,
                                                                 node_process) -> None:
    arguments = ["-p", "pose_message:=Odometry"] if "extrinsics" in parameter else []
    process = node_process(executable, "--ros-args", "-p", parameter, *arguments)
    process.process.wait(timeout=30.0)
    assert process.stop() == 2, process.text
    assert message in process.text and "Traceback" not in process.text


# --- the camera pose from TF (real tf2_ros, built from SAILOR_UPSTREAM) ---------------------------


def transform_message(parent: str, child: str, pose: Pose, stamp: Any) -> Any:
    from geometry_msgs.msg import Quaternion, TransformStamped, Vector3

    message = TransformStamped(header=Header(stamp=stamp, frame_id=parent), child_frame_id=child)
    x, y, z, w = (float(value) for value in pose.quaternion_xyzw)
    tx, ty, tz = (float(value) for value in pose.translation)
    message.transform.translation = Vector3(x=tx, y=ty, z=tz)
    message.transform.rotation = Quaternion(x=x, y=y, z=z, w=w)
    return message


def test_percepts_from_the_camera_pose_in_tf_through_static_and_moving_frames(
    upstream_stack, ros_probe, node_process, subscribe
) -> None:
    """map -> base_link moves (on /tf); base_link -> camera_link -> camera_color_optical_frame is
    the robot's description (on /tf_static). A frame whose stamp TF cannot reach is dropped, with
    one line naming the frames and the latest stamp TF has."""
    upstream_stack("tf2_ros", "tf2_msgs.msg")
    import tf2_ros
    from tf2_msgs.msg import TFMessage

    namespace = "/tf_camera"
    percept_arrays = subscribe(PerceptArray, f"{namespace}/percepts")
    generator = node_process("percept_generator", "--ros-args", "-r", f"__ns:={namespace}",
                             "-p", "pose_source:=tf", "-p", "tracker_frame_rate:=10.0")
    base_to_camera_link = Pose(np.eye(3), CAMERA_EXTRINSICS[:3])
    camera_link_to_optical = Pose.from_quaternion(CAMERA_EXTRINSICS[3:])
    base_to_optical = base_to_camera_link.compose(camera_link_to_optical)
    np.testing.assert_allclose(base_to_optical.translation, CAMERA_EXTRINSICS[:3])
    static = tf2_ros.StaticTransformBroadcaster(ros_probe.node)
    static.sendTransform([
        transform_message("base_link", "camera_link", base_to_camera_link, seconds_to_stamp(0.0)),
        transform_message("camera_link", "camera_color_optical_frame", camera_link_to_optical, seconds_to_stamp(0.0)),
    ])
    camera = SceneCamera(ros_probe, namespace)
    camera.pose = ros_probe.node.create_publisher(TFMessage, "/tf", 100)  # the robot's moving base
    assert camera.wait_until_connected(), generator.text

    frame_count, start = 10, 4000.0
    poses = [camera_pose((0.05 * k, -0.3 + 0.06 * k, 0.9 + 0.02 * k), -6.0 + 1.2 * k) for k in range(frame_count)]
    for k, pose in enumerate(poses):
        stamp = seconds_to_stamp(start + 0.1 * k)
        map_to_base = pose.compose(base_to_optical.inverse())
        moving = TFMessage(transforms=[transform_message("map", "base_link", map_to_base, stamp)])
        camera.pose.publish(moving)
        time.sleep(0.02)  # the transform reaches the buffer before the detector has answered
        camera.publish(start + 0.1 * k, pose, render(pose), pose=moving)
        time.sleep(0.08)
    ros_probe.wait_for(lambda: any(stamp_of(a) == pytest.approx(start + 0.9) for a in percept_arrays), timeout=5.0)
    # A frame far past the last transform: dropped, said once, with what TF has; then one with its
    # transform again, whose percepts say the node has handled the late one.
    last = poses[-1]
    camera.publish(start + 60.0, last, render(last), pose=TFMessage())
    again = TFMessage(transforms=[transform_message("map", "base_link", last.compose(base_to_optical.inverse()),
                                                    seconds_to_stamp(start + 1.0))])
    camera.pose.publish(again)
    time.sleep(0.02)
    camera.publish(start + 1.0, last, render(last), pose=again)
    ros_probe.wait_for(lambda: any(stamp_of(a) == pytest.approx(start + 1.0) for a in percept_arrays), timeout=5.0)
    assert generator.stop() == 0
    log = generator.text

    assert len(percept_arrays) >= frame_count - 2, log
    assert all(stamp_of(array) < start + 30.0 for array in percept_arrays)  # the late frame was dropped
    for array in percept_arrays:
        (percept,) = percepts_from_message(array)
        np.testing.assert_allclose(percept.position, PLATE_CENTRE, atol=0.02, err_msg=log)
    assert "no transform from 'camera_color_optical_frame' to 'map' at 4060.000" in log, log
    assert "the latest transform between them is at 4000.9" in log, log
    assert "frame(s) without a transform since the start" in log and "Traceback" not in log
