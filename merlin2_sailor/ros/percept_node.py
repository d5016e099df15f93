"""percept_generator: detections + RGB-D + camera pose -> percepts in the world frame.

Inputs (relative names, remappable): the colour image, registered depth (``depth/image_raw``) or
an organised cloud (``depth/points``), ``color/camera_info``, the detector's ``detections`` and
the camera pose: a PoseStamped of the optical frame in the world (``camera_pose``), an Odometry
(``odom``) combined with the static ``camera_extrinsics``, or tf2 where it is installed. Image,
depth, detections and pose are paired by stamp with the core's approximate-time synchroniser;
the camera info is taken as the latest one, since it changes only with a new calibration.

Outputs: a PerceptArray on ``percepts`` for every synchronised frame (header: image stamp and
world frame; an empty array means "seen, nothing there", which the anchoring layer's Track
process needs), and its 3D boxes as a MarkerArray on ``percept_markers``.

Why the tracker runs here and not in the detector node: ByteTrack must see every frame's
detections once and in order, and this node is the one that publishes the ids. It runs in the
detections callback, before synchronisation, so a frame that later fails to pair with its depth
or pose still advances the tracks; and it tracks whatever detector feeds it (SSD, YOLO, an
external node), so no backend needs tracking of its own. Its lost-track buffer counts updates,
so its frame rate is the rate of the frames it is fed: ``tracker_frame_rate``, or estimated from
the stamps of the first detection arrays (the image stamps of the frames it tracks).

Every bad message (wrong encoding, NaN pose, a frame whose depth does not match its image) is
logged at most once per few seconds and dropped; the node keeps going with the next frame.
"""

from __future__ import annotations

import dataclasses
import math
import threading
import time
from collections import Counter
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from builtin_interfaces.msg import Time as TimeMessage
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import Odometry
from rclpy.node import Node
from sensor_msgs.msg import CameraInfo, Image, PointCloud2
from std_msgs.msg import Header
from visualization_msgs.msg import MarkerArray

from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.diagnostics.topic_statistics import TopicStatistics
from merlin2_sailor.errors import ConfigurationError, InvalidInputError
from merlin2_sailor.perception.box3d import Box3DConfig, RejectionReason
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor.perception.percept_generator import PerceptBatch, PerceptGenerator, PerceptGeneratorConfig
from merlin2_sailor.perception.synchroniser import ApproximateTimeSynchroniser, MatchedSet, SynchroniserConfig
from merlin2_sailor.perception.tracker import ByteTrackAdapter, ByteTrackConfig
from merlin2_sailor.ros.conversions import (
    camera_info_to_intrinsics,
    depth_to_metres,
    image_to_array,
    image_to_rgb,
    odometry_to_camera_pose,
    percept_markers,
    percepts_to_message,
    point_cloud_to_array,
    pose_from_message,
    stamp_to_seconds,
)
from merlin2_sailor.ros.conversions.detection_sources import (
    DETECTION_TYPES,
    NUMERIC_CLASS_IDS,
    detection_source,
)
from merlin2_sailor.ros.conversions.detection_sources import (
    SAILOR as SAILOR_DETECTIONS,
)
from merlin2_sailor.ros.newest_frame_mailbox import NewestFrameMailbox
from merlin2_sailor.ros.node_runner import run_node
from merlin2_sailor.ros.parameters import declare_parameter
from merlin2_sailor.ros.qos import SENSOR_DATA
from merlin2_sailor.ros.tf_poses import TfCameraPoses
from merlin2_sailor_interfaces.msg import PerceptArray

NODE_NAME = "percept_generator"
WARNING_PERIOD_SECONDS = 5.0  # bad input is logged at most this often, whatever the camera rate
#: Messages stamped further than this ahead of the node's clock are refused: the synchroniser
#: drops everything older than the last set it emitted, so one frame from a clock that jumped
#: ahead would otherwise silence the node until the real time caught up with it.
FUTURE_STAMP_LIMIT_SECONDS = 10.0
#: Detection arrays whose stamps estimate the tracker's frame rate when it is not configured.
RATE_ESTIMATION_FRAMES = 5
#: The optical frame at the robot base's origin looking forward: REP 103 base (x forward, z up).
FORWARD_OPTICAL_EXTRINSICS = [0.0, 0.0, 0.0, -0.5, 0.5, -0.5, 0.5]
DEFAULT_SLOP_SECONDS = 0.03
"""Largest stamp spread of a synchronised frame when no parameter file sets ``slop``."""

DEPTH_SOURCES = ("depth_image", "point_cloud")
POSE_SOURCES = ("topic", "tf")
POSE_MESSAGES = ("PoseStamped", "Odometry")
TRACKERS = ("bytetrack", "none")
_INPUTS = ("image", "depth", "detections", "pose")


class PerceptNode(Node):
    def __init__(self) -> None:
        super().__init__(NODE_NAME)
        self._world_frame = declare_parameter(
            self, "world_frame", "map", "Fixed frame of the percepts; camera poses must be given in it.",
        )
        depth_source = self._choice("depth_source", "depth_image", DEPTH_SOURCES,
                                    "Depth input: depth_image (depth/image_raw) or point_cloud (depth/points).")
        pose_source = self._choice("pose_source", "topic", POSE_SOURCES,
                                   "Camera pose from a topic (see pose_message) or from tf2 (needs tf2_ros).")
        pose_message = self._choice("pose_message", "PoseStamped", POSE_MESSAGES,
                                    "With pose_source topic: PoseStamped on camera_pose (the optical frame's "
                                    "pose) or Odometry on odom (with camera_extrinsics).")
        detections_type = self._choice(
            "detections_type", SAILOR_DETECTIONS, DETECTION_TYPES,
            "Message type on detections: sailor (merlin2_sailor_interfaces/DetectionArray), yolo_msgs "
            "(yolo_ros' DetectionArray) or vision_msgs (Detection2DArray).")
        numeric_class_ids = self._choice(
            "numeric_class_ids", "coco", NUMERIC_CLASS_IDS,
            "vision_msgs only: how a class_id that is a number is read: coco (YOLO's 0-79) or coco_tf "
            "(TensorFlow's 1-90); a class_id that is a name is taken as it is.")
        self._detections = detection_source(detections_type, numeric_class_ids)
        extrinsics = declare_parameter(
            self, "camera_extrinsics", FORWARD_OPTICAL_EXTRINSICS,
            "Odometry only: pose of the camera optical frame in the robot base frame, [x, y, z, qx, qy, qz, qw].",
        )
        slop = declare_parameter(self, "slop", DEFAULT_SLOP_SECONDS,
                                 "Largest stamp spread (s) of a synchronised frame.", minimum=0.0, maximum=1.0)
        queue_size = declare_parameter(
            self, "sync_queue_size", 15,
            "Messages kept per input while waiting for a match; must cover the detector's latency.",
            minimum=1, maximum=1000,
        )
        tracker = self._declare_tracker()
        self._publish_crops = declare_parameter(self, "publish_crops", True, "Send each percept's RGB crop.")
        box3d = self._declare_box3d_config()
        report_period = declare_parameter(self, "report_period", 10.0, "Seconds between two statistics log lines.",
                                          minimum=0.5, maximum=3600.0)

        self._generator = PerceptGenerator(PerceptGeneratorConfig(box3d=box3d, world_frame=self._world_frame))
        self._synchroniser = ApproximateTimeSynchroniser(_INPUTS, SynchroniserConfig(slop, queue_size))
        self._depth_source = depth_source
        self._intrinsics: CameraIntrinsics | None = None
        self._camera_info_key: tuple[Any, ...] | None = None
        self._image_frame_id = ""
        self._tf_poses: TfCameraPoses | None = None

        self._published = TopicStatistics(window_seconds=report_period)
        self._dropped_reasons: Counter[str] = Counter()
        self._skipped_frames = 0
        # Matched frames go to a worker through a one-slot mailbox: when percept generation falls
        # behind the camera, the newest frame wins and the ones it replaced are counted.
        self._statistics_lock = threading.Lock()
        self._mailbox = NewestFrameMailbox()
        self._worker = threading.Thread(target=self._work, name="percept-generator", daemon=True)
        self._worker.start()
        self._report_period = report_period
        self._last_warning: dict[str, float] = {}

        self._percept_publisher = self.create_publisher(PerceptArray, "percepts", SENSOR_DATA)
        self._marker_publisher = self.create_publisher(MarkerArray, "percept_markers", SENSOR_DATA)
        self.create_subscription(Image, "color/image_raw", self._on_image, SENSOR_DATA)
        if depth_source == "depth_image":
            self.create_subscription(Image, "depth/image_raw", self._on_depth_image, SENSOR_DATA)
        else:
            self.create_subscription(PointCloud2, "depth/points", self._on_point_cloud, SENSOR_DATA)
        self.create_subscription(CameraInfo, "color/camera_info", self._on_camera_info, SENSOR_DATA)
        self.create_subscription(self._detections.message_type, "detections", self._on_detections, SENSOR_DATA)
        self._subscribe_pose(pose_source, pose_message, extrinsics)
        self.create_timer(report_period, self._report)
        self.get_logger().info(
            f"percepts in '{self._world_frame}' from {depth_source}, pose from "
            f"{pose_message if pose_source == 'topic' else 'tf2'}, tracker {tracker}, detections as "
            f"{self._detections.type_name}"
        )

    # --- parameters -----------------------------------------------------------------------------

    def _choice(self, name: str, default: str, choices: Sequence[str], description: str) -> str:
        value = declare_parameter(self, name, default, description)
        if value not in choices:
            raise ConfigurationError(f"parameter '{name}' must be one of {', '.join(choices)}, got '{value}'")
        return value

    def _declare_tracker(self) -> str:
        tracker = self._choice("tracker", "bytetrack", TRACKERS,
                               "bytetrack, or none to keep the ids the detections already carry.")
        frame_rate = declare_parameter(
            self, "tracker_frame_rate", 0.0,
            "Frames per second the tracker is fed; 0 estimates it from the first detection stamps.",
            minimum=0.0, maximum=1000.0,
        )
        id_prefix = declare_parameter(self, "tracker_id_prefix", "",
                                      "Prefix of tracker ids, to keep several cameras' ids apart.")
        new_track_threshold = declare_parameter(
            self, "tracker_new_track_threshold", ByteTrackConfig().new_track_threshold,
            "Score from which an unmatched detection starts a track (0.5: every published detection; faster).",
            minimum=0.0, maximum=1.0)
        self._tracker_config: ByteTrackConfig | None = None
        self._tracker: ByteTrackAdapter | None = None
        self._tracker_rate_known = frame_rate > 0.0
        self._detection_stamps = TopicStatistics(window_seconds=3600.0)  # stamps of the rate estimate
        if tracker == "bytetrack":
            # Built now even when the rate is still unknown, so a missing package or a bad threshold
            # stops the node at start-up rather than at the first detection.
            self._tracker_config = ByteTrackConfig(frame_rate=frame_rate or 30.0, id_prefix=id_prefix,
                                                   new_track_threshold=new_track_threshold)
            self._tracker = ByteTrackAdapter(self._tracker_config)
        return tracker

    def _declare_box3d_config(self) -> Box3DConfig:
        return Box3DConfig(
            depth_band_half_width=declare_parameter(
                self, "depth_band_half_width", 0.2,
                "Points farther than this (m) from the object's depth are background.", minimum=0.001, maximum=10.0),
            minimum_valid_pixels=declare_parameter(
                self, "minimum_valid_pixels", 20, "Fewer usable depth pixels and the detection is dropped.",
                minimum=1, maximum=1_000_000),
            minimum_depth_coverage=declare_parameter(
                self, "minimum_depth_coverage", 0.25,
                "Fraction of a box's centre that must have usable depth; below it the object is out of range.",
                minimum=0.0, maximum=1.0),
            minimum_depth=declare_parameter(self, "minimum_depth", 0.1, "Nearest trusted depth (m).",
                                            minimum=0.0, maximum=100.0),
            maximum_depth=declare_parameter(self, "maximum_depth", 20.0, "Farthest trusted depth (m).",
                                            minimum=0.0, maximum=1000.0),
        )

    def _subscribe_pose(self, pose_source: str, pose_message: str, extrinsics: Sequence[float]) -> None:
        if pose_source == "tf":
            self._tf_poses = TfCameraPoses(
                self, self._world_frame, alternative="pose_source 'topic': camera_pose as PoseStamped, or odom as "
                "Odometry with camera_extrinsics")
            return  # poses are looked up when detections arrive, see _on_detections
        if pose_message == "PoseStamped":
            self.create_subscription(PoseStamped, "camera_pose", self._pose_callback(
                lambda message: pose_from_message(message.pose)), SENSOR_DATA)
            return
        try:
            base_to_camera = Pose.from_quaternion(extrinsics[3:], extrinsics[:3]) if len(extrinsics) == 7 else None
        except InvalidInputError as error:
            raise ConfigurationError(f"camera_extrinsics: {error}") from error
        if base_to_camera is None:
            raise ConfigurationError(f"camera_extrinsics must be [x, y, z, qx, qy, qz, qw], got {list(extrinsics)}")
        self.create_subscription(Odometry, "odom", self._pose_callback(
            lambda message: odometry_to_camera_pose(message, base_to_camera)), SENSOR_DATA)

    # --- input callbacks: convert, validate, push to the synchroniser --------------------------------

    def _on_image(self, message: Image) -> None:
        self._push("image", message.header, lambda: (message.header.stamp, image_to_rgb(message)))
        self._image_frame_id = message.header.frame_id

    def _on_depth_image(self, message: Image) -> None:
        self._push("depth", message.header, lambda: depth_to_metres(image_to_array(message), message.encoding))

    def _on_point_cloud(self, message: PointCloud2) -> None:
        def points() -> np.ndarray:
            # The cloud is used with the camera's pose, so it must be in the camera's optical frame.
            if self._image_frame_id and message.header.frame_id != self._image_frame_id:
                raise InvalidInputError(
                    f"point cloud in frame '{message.header.frame_id}' but images in '{self._image_frame_id}'; "
                    "publish the cloud registered to the colour camera's optical frame"
                )
            return point_cloud_to_array(message)

        self._push("depth", message.header, points)

    def _on_camera_info(self, message: CameraInfo) -> None:
        key = (tuple(message.k), message.width, message.height)
        if key == self._camera_info_key:
            return  # unchanged calibration: nothing to convert
        try:
            self._intrinsics = camera_info_to_intrinsics(message)
            self._camera_info_key = key
        except InvalidInputError as error:
            self._warn("camera_info", f"camera info dropped: {error}")

    def _pose_callback(self, to_pose: Callable[[Any], Pose]) -> Callable[[Any], None]:
        def on_pose(message: Any) -> None:
            def camera_pose() -> Pose:
                if message.header.frame_id != self._world_frame:
                    raise InvalidInputError(
                        f"pose given in frame '{message.header.frame_id}', but world_frame is '{self._world_frame}'"
                    )
                return to_pose(message)

            self._push("pose", message.header, camera_pose)

        return on_pose

    def _on_detections(self, message: Any) -> None:
        try:
            self._refuse_future_stamp(message.header)  # before the tracker sees the stamp
            detections = self._detections.read(message)
        except InvalidInputError as error:
            self._warn("detections", f"detections dropped: {error}")
            return
        stamp = stamp_to_seconds(message.header.stamp)
        detections = self._track(detections, stamp)
        if self._tf_poses is not None:
            # Looked up now rather than when the image arrived: by the time the detector has
            # answered, the transform at the image stamp has reached the tf buffer.
            self._push("pose", message.header, lambda: self._tf_poses.lookup(message.header.frame_id,
                                                                             message.header.stamp))
        self._push("detections", message.header, lambda: detections)

    def _push(self, input_name: str, header: Header, convert: Callable[[], Any]) -> None:
        """Convert a message and hand it to the synchroniser; a bad message is logged and dropped."""
        try:
            self._refuse_future_stamp(header)
            value = convert()
            matched = self._synchroniser.push(input_name, stamp_to_seconds(header.stamp), value)
        except InvalidInputError as error:
            self._warn(input_name, f"{input_name} dropped: {error}")
            return
        if matched is not None:
            self._mailbox.put(matched)

    def _work(self) -> None:
        while (matched := self._mailbox.take()) is not None:
            try:
                self._process(matched)
            except Exception as error:  # noqa: BLE001 - one bad frame must not stop percept generation
                self._warn("worker", f"frame dropped: percept generation failed: {error!r}")

    def _refuse_future_stamp(self, header: Header) -> None:
        lead = stamp_to_seconds(header.stamp) - self._now()
        if lead > FUTURE_STAMP_LIMIT_SECONDS:
            raise InvalidInputError(
                f"stamped {lead:.0f} s ahead of this node's clock (more than {FUTURE_STAMP_LIMIT_SECONDS:g} s); "
                "check the camera driver's clock"
            )

    # --- tracking -------------------------------------------------------------------------------

    def _track(self, detections: list[Detection], stamp: float) -> list[Detection]:
        if self._tracker is None:
            return detections  # tracker "none": keep the ids the detector gave
        if not self._tracker_rate_known and not self._estimate_tracker_rate(stamp):
            return [dataclasses.replace(detection, tracker_id="") for detection in detections]
        return self._tracker.update(detections, stamp)

    def _estimate_tracker_rate(self, stamp: float) -> bool:
        """Feed one stamp to the rate estimate; rebuild the tracker once it is known."""
        self._detection_stamps.record(stamp)
        report = self._detection_stamps.report(stamp)
        if report.messages < RATE_ESTIMATION_FRAMES or report.rate_hz <= 0.0:
            return False
        assert self._tracker_config is not None
        self._tracker_config = dataclasses.replace(self._tracker_config, frame_rate=report.rate_hz)
        self._tracker = ByteTrackAdapter(self._tracker_config)
        self._tracker_rate_known = True
        self.get_logger().info(f"tracking at {report.rate_hz:.1f} frames per second (estimated from stamps)")
        return True

    # --- a synchronised frame -------------------------------------------------------------------

    def _process(self, matched: MatchedSet) -> None:
        inputs = matched.messages
        image_stamp, image = inputs["image"]  # percepts carry the image's stamp, not the set's newest
        stamp = stamp_to_seconds(image_stamp)
        detections: list[Detection] = inputs["detections"]
        depth, camera_to_world = inputs["depth"], inputs["pose"]
        if self._depth_source == "depth_image":
            if self._intrinsics is None:
                self._skip("no camera info received yet on color/camera_info")
                return
            batch = self._generator.generate(detections, image, depth, self._intrinsics, camera_to_world, stamp)
        else:
            batch = self._generator.generate_from_points(detections, image, depth, camera_to_world, stamp)
        self._publish(batch, image_stamp)

    def _publish(self, batch: PerceptBatch, image_stamp: TimeMessage) -> None:
        frame_problems = [drop for drop in batch.dropped if drop.reason is RejectionReason.INVALID_FRAME]
        if frame_problems:
            # The frame as a whole is unusable: publishing "nothing seen" would be a false negative.
            self._skip(frame_problems[0].detail)
            return
        for drop in batch.dropped:
            with self._statistics_lock:
                self._dropped_reasons[drop.reason.value] += 1
            self._warn(
                f"percept:{drop.reason.value}",
                f"detection '{drop.detection.class_name}' dropped ({drop.reason.value}): {drop.detail}",
            )
        percepts = batch.percepts
        if not self._publish_crops:
            percepts = tuple(dataclasses.replace(p, crop=np.zeros((0, 0, 3), dtype=np.uint8)) for p in percepts)
        header = Header(stamp=image_stamp, frame_id=self._world_frame)
        self._percept_publisher.publish(percepts_to_message(percepts, header))
        self._marker_publisher.publish(percept_markers(percepts, header))
        with self._statistics_lock:
            self._published.record(self._now(), stamp_to_seconds(image_stamp))

    def _skip(self, reason: str) -> None:
        with self._statistics_lock:
            self._skipped_frames += 1
        self._warn("frame", f"frame skipped: {reason}")

    def _warn(self, key: str, text: str) -> None:
        """Log a warning unless one with the same key was logged in the last few seconds.

        Keyed by what went wrong rather than by call site (rclpy's throttle), so a bad depth
        stream does not hide a bad pose stream that is reported by the same line of code.
        """
        now = time.monotonic()
        if now - self._last_warning.get(key, -math.inf) >= WARNING_PERIOD_SECONDS:
            self._last_warning[key] = now
            self.get_logger().warning(text)

    # --- reporting --------------------------------------------------------------------------------

    def _report(self) -> None:
        with self._statistics_lock:
            report = self._published.report(self._now())
            dropped_reasons = dict(self._dropped_reasons)
            skipped = self._skipped_frames
        busy_drops = self._mailbox.dropped
        if report.total_messages == 0 and skipped == 0 and busy_drops == 0:
            return
        parts = [f"{report.messages} percept arrays in the last {self._report_period:g} s ({report.rate_hz:.1f} Hz)"]
        if report.mean_age_seconds is not None:
            parts.append(f"image-to-percepts latency {1000.0 * report.mean_age_seconds:.0f} ms")
        if dropped_reasons:
            parts.append("detections dropped since start: " + ", ".join(
                f"{reason} {count}" for reason, count in sorted(dropped_reasons.items())))
        if skipped:
            parts.append(f"{skipped} frames skipped since start")
        if busy_drops:
            parts.append(f"{busy_drops} frames dropped since start while busy (the newest frame wins)")
        self.get_logger().info(", ".join(parts))

    def destroy_node(self) -> None:
        self._mailbox.close()
        self._worker.join(timeout=5.0)
        super().destroy_node()

    def _now(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9


def main(argv: Sequence[str] | None = None) -> int:
    return run_node(PerceptNode, argv)


if __name__ == "__main__":
    raise SystemExit(main())
