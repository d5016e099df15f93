"""BagSource: the frames of a rosbag2 bag, as the percept generator node would pair them.

A robot's bag holds what its nodes heard: colour and registered depth images, the camera info,
the camera pose (a PoseStamped of the optical frame, an Odometry of the base with the camera's
extrinsics, or TF) and, where a detector ran, its detections. This source pairs them the way
the percept generator node does: each colour image takes the depth image, pose and detections
nearest its stamp within ``slop`` (a frame missing one of them is skipped and counted, as the
node's synchroniser would drop it), and the latest camera info. Recorded detections are used as
they are (the detector is then not run); without them the replay's detector runs on the images.

A first pass reads the small messages whole and only the stamps of the images; frames are then
streamed, so a bag of any length replays in the memory of a few frames. Every message goes
through the nodes' own conversions, so a wrong encoding or a malformed message is the same
error the node would log; here the frame is skipped with one line per kind of problem.
"""

from __future__ import annotations

import bisect
import sys
from collections import Counter
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field, fields
from typing import Any, ClassVar

import numpy as np

from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import ConfigurationError, InvalidInputError
from merlin2_sailor.perception.box3d import Box3DConfig
from merlin2_sailor.perception.depth import depth_to_metres
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor.perception.percept_generator import PerceptGeneratorConfig
from merlin2_sailor.ros.bags import BagReader
from merlin2_sailor.ros.conversions import (
    camera_info_to_intrinsics,
    image_to_array,
    image_to_rgb,
    odometry_to_camera_pose,
    pose_from_message,
    stamp_to_seconds,
    transform_to_pose,
)
from merlin2_sailor.ros.conversions.detection_sources import DETECTION_TYPES, detection_source
from merlin2_sailor.ros.percept_node import DEFAULT_SLOP_SECONDS, FORWARD_OPTICAL_EXTRINSICS
from merlin2_sailor_demos.replay.source import ReplayFrame, ReplaySource

TF_TOPIC, TF_STATIC_TOPIC = "/tf", "/tf_static"
#: Detection message type in a bag -> the percept generator's detections_type.
DETECTIONS_TYPE_OF_MESSAGE = {
    "merlin2_sailor_interfaces/msg/DetectionArray": "sailor",
    "yolo_msgs/msg/DetectionArray": "yolo_msgs",
    "vision_msgs/msg/Detection2DArray": "vision_msgs",
}
POSE_TYPES = ("geometry_msgs/msg/PoseStamped", "nav_msgs/msg/Odometry")


@dataclass(frozen=True)
class BagSourceConfig:
    """Where the bag is and which of its topics are what; the defaults are the names the
    simulated house publishes (and ``sailor demo --record`` records).

    ``pose_topic`` empty: the camera pose comes from TF (``world_frame`` <- ``camera_frame``, the
    image's frame when empty). ``detections_topic`` empty, or not in the bag: the detector runs.
    ``percept_parameters``: the percept generator node's parameters (its files' values).
    """

    data: str = ""
    color_topic: str = "/camera/color/image_raw"
    depth_topic: str = "/camera/depth/image_raw"
    camera_info_topic: str = "/camera/color/camera_info"
    pose_topic: str = "/camera/camera_pose"
    detections_topic: str = "/camera/detections"
    camera_frame: str = ""
    percept_parameters: Mapping[str, Any] = field(default_factory=dict)


@dataclass(frozen=True, slots=True)
class _FramePlan:
    """One frame: the stamps (ns) of its colour and depth images and what was paired with them."""

    color_ns: int
    depth_ns: int
    intrinsics: CameraIntrinsics
    camera_to_world: Pose
    detections: tuple[Detection, ...] | None


class BagSource(ReplaySource):
    config_class: ClassVar[type] = BagSourceConfig
    name: ClassVar[str] = "bag"
    frame_rate: float = 15.0  # set from the bag's image stamps
    default_frames: int = 0  # every frame of the bag

    def __init__(self, config: BagSourceConfig) -> None:
        if not config.data:
            raise ConfigurationError("name the bag to replay: sailor replay bag PATH")
        self.config = config
        parameters = dict(config.percept_parameters)
        self.world_frame = str(parameters.get("world_frame", "map"))
        self.slop = float(parameters.get("slop", DEFAULT_SLOP_SECONDS))
        self._numeric_class_ids = str(parameters.get("numeric_class_ids", "coco"))
        extrinsics = parameters.get("camera_extrinsics", FORWARD_OPTICAL_EXTRINSICS)
        self._base_to_camera = Pose.from_quaternion(extrinsics[3:], extrinsics[:3])
        self.skipped: Counter[str] = Counter()
        self._said: set[str] = set()
        self._bag = BagReader(config.data)
        with self._bag as bag:
            self._plans = self._plan_frames(bag)
        if not self._plans:
            reasons = ", ".join(f"{count} {reason}" for reason, count in self.skipped.items()) or "no colour images"
            raise ConfigurationError(f"the bag {config.data} has no frame to replay ({reasons})")
        period = float(np.median(np.diff([plan.color_ns for plan in self._plans]))) / 1e9 if len(self._plans) > 1 else 0
        if period > 0:
            self.frame_rate = 1.0 / period
        self.default_frames = len(self._plans)

    # --- ReplaySource ---------------------------------------------------------------------------

    @property
    def description(self) -> str:
        detections = ("recorded detections on " + self.config.detections_topic if self.uses_recorded_detections
                      else "the replay's detector")
        pose = f"pose from {self.config.pose_topic}" if self.config.pose_topic else f"pose from TF ({self.world_frame})"
        return (f"rosbag2 bag {self.config.data}: {len(self._plans)} frames at {self.frame_rate:.1f} Hz from "
                f"{self.config.color_topic} and {self.config.depth_topic}, {pose}, {detections}")

    @property
    def frame_count(self) -> int:
        return len(self._plans)

    @property
    def uses_recorded_detections(self) -> bool:
        return bool(self._plans) and self._plans[0].detections is not None

    def frames(self, indices: Sequence[int]) -> Iterator[ReplayFrame]:
        plans = [self._plans[index] for index in indices]
        wanted_colors = {plan.color_ns for plan in plans}
        depth_uses = Counter(plan.depth_ns for plan in plans)  # a depth image may serve two frames
        colors: dict[int, Any] = {}
        depths: dict[int, Any] = {}
        position = 0
        with self._bag as bag:
            for item in bag.messages((self.config.color_topic, self.config.depth_topic)):
                stamp = _stamp_ns(item.message)
                if item.topic == self.config.color_topic and stamp in wanted_colors:
                    colors[stamp] = item.message
                elif item.topic == self.config.depth_topic and stamp in depth_uses:
                    depths[stamp] = item.message
                # Frames in order, each as soon as both of its images have been read.
                while position < len(plans) and plans[position].color_ns in colors \
                        and plans[position].depth_ns in depths:
                    plan = plans[position]
                    frame = self._frame(indices[position], plan, colors.pop(plan.color_ns), depths[plan.depth_ns])
                    depth_uses[plan.depth_ns] -= 1
                    if depth_uses[plan.depth_ns] == 0:
                        depths.pop(plan.depth_ns)
                    position += 1
                    if frame is not None:
                        yield frame

    def percept_config(self) -> PerceptGeneratorConfig:
        """The percept generator node's thresholds, from the parameters it would be given."""
        parameters = dict(self.config.percept_parameters)
        box_fields = {item.name for item in fields(Box3DConfig)}
        box3d = Box3DConfig(**{name: value for name, value in parameters.items() if name in box_fields})
        return PerceptGeneratorConfig(box3d=box3d, world_frame=self.world_frame)

    def settings(self) -> dict[str, Any]:
        return {"bag": self.config.data, "topics": {
            "color": self.config.color_topic, "depth": self.config.depth_topic,
            "camera_info": self.config.camera_info_topic, "pose": self.config.pose_topic or "TF",
            "detections": self.config.detections_topic if self.uses_recorded_detections else "(the detector)"},
            "frames_skipped": dict(self.skipped), "world_frame": self.world_frame, "slop": self.slop}

    # --- The first pass -------------------------------------------------------------------------

    def _plan_frames(self, bag: BagReader) -> list[_FramePlan]:
        config = self.config
        bag.require(config.color_topic, "colour images", "--color-topic")
        bag.require(config.depth_topic, "registered depth images", "--depth-topic")
        bag.require(config.camera_info_topic, "the camera info", "--camera-info-topic")
        pose_type = ""
        if config.pose_topic:
            pose_type = bag.require(config.pose_topic, "the camera pose", "--pose-topic ('' for TF)")
            if pose_type not in POSE_TYPES:
                raise ConfigurationError(
                    f"the bag's pose topic {config.pose_topic} holds {pose_type}; a camera pose is one of "
                    f"{', '.join(POSE_TYPES)} (or TF: --pose-topic '')")
        elif TF_TOPIC not in bag.topics and TF_STATIC_TOPIC not in bag.topics:
            raise ConfigurationError(f"the bag has neither {TF_TOPIC} nor {TF_STATIC_TOPIC}: name a pose topic "
                                     "with --pose-topic")
        detections = None
        if config.detections_topic and config.detections_topic in bag.topics:
            message_type = bag.topics[config.detections_topic]
            if message_type not in DETECTIONS_TYPE_OF_MESSAGE:
                raise ConfigurationError(
                    f"the bag's detections topic {config.detections_topic} holds {message_type}; detections are "
                    f"one of {', '.join(DETECTIONS_TYPE_OF_MESSAGE)} ({', '.join(DETECTION_TYPES)})")
            detections = detection_source(DETECTIONS_TYPE_OF_MESSAGE[message_type], self._numeric_class_ids)

        color_stamps: list[tuple[int, str]] = []
        depth_stamps: list[int] = []
        infos: list[tuple[int, CameraIntrinsics]] = []
        poses: list[tuple[int, Pose]] = []
        detected: dict[int, list[Detection]] = {}
        transforms: list[tuple[Any, bool]] = []
        topics = [config.color_topic, config.depth_topic, config.camera_info_topic]
        topics += [config.pose_topic] if config.pose_topic else [TF_TOPIC, TF_STATIC_TOPIC]
        topics += [config.detections_topic] if detections is not None else []
        for item in bag.messages(topics):
            message = item.message
            try:
                if item.topic == config.color_topic:
                    color_stamps.append((_stamp_ns(message), message.header.frame_id))
                elif item.topic == config.depth_topic:
                    depth_stamps.append(_stamp_ns(message))
                elif item.topic == config.camera_info_topic:
                    infos.append((_stamp_ns(message), camera_info_to_intrinsics(message)))
                elif item.topic == config.pose_topic:
                    poses.append((_stamp_ns(message), self._pose_of(message, pose_type)))
                elif item.topic in (TF_TOPIC, TF_STATIC_TOPIC):
                    transforms += [(transform, item.topic == TF_STATIC_TOPIC) for transform in message.transforms]
                elif detections is not None and item.topic == config.detections_topic:
                    detected[_stamp_ns(message)] = detections.read(message)
            except InvalidInputError as error:
                self._skip(f"bad message on {item.topic}", str(error))
        lookup = _TfLookup(transforms, self.world_frame) if not config.pose_topic else None
        return self._pair(color_stamps, depth_stamps, infos, poses, detected if detections else None, lookup)

    def _pose_of(self, message: Any, pose_type: str) -> Pose:
        if pose_type == POSE_TYPES[0]:
            return pose_from_message(message.pose)
        return odometry_to_camera_pose(message, self._base_to_camera)

    def _pair(self, color_stamps: list[tuple[int, str]], depth_stamps: list[int],
              infos: list[tuple[int, CameraIntrinsics]], poses: list[tuple[int, Pose]],
              detected: dict[int, list[Detection]] | None, lookup: _TfLookup | None) -> list[_FramePlan]:
        slop_ns = int(self.slop * 1e9)
        depth_sorted = sorted(depth_stamps)
        poses.sort(key=lambda item: item[0])
        pose_stamps = [stamp for stamp, _ in poses]
        infos.sort(key=lambda item: item[0])
        info_stamps = [stamp for stamp, _ in infos]
        detection_stamps = sorted(detected) if detected is not None else []
        plans = []
        for color_ns, frame_id in sorted(set(color_stamps)):
            depth_ns = _nearest(depth_sorted, color_ns, slop_ns)
            if depth_ns is None:
                self._skip("no depth image within the slop")
                continue
            if not infos:
                self._skip("no camera info")
                continue
            info_index = max(0, bisect.bisect_right(info_stamps, color_ns + slop_ns) - 1)
            if lookup is not None:
                try:
                    pose = lookup.pose(self.config.camera_frame or frame_id, color_ns)
                except InvalidInputError as error:
                    self._skip("no camera pose in TF at the image stamp", str(error))
                    continue
            else:
                pose_ns = _nearest(pose_stamps, color_ns, slop_ns)
                if pose_ns is None:
                    self._skip("no camera pose within the slop")
                    continue
                pose = poses[bisect.bisect_left(pose_stamps, pose_ns)][1]
            frame_detections = None
            if detected is not None:
                detections_ns = _nearest(detection_stamps, color_ns, slop_ns)
                if detections_ns is None:
                    self._skip("no detections within the slop")
                    continue
                frame_detections = tuple(detected[detections_ns])
            plans.append(_FramePlan(color_ns, depth_ns, infos[info_index][1], pose, frame_detections))
        return plans

    # --- Frames ---------------------------------------------------------------------------------

    def _frame(self, index: int, plan: _FramePlan, color_message: Any, depth_message: Any) -> ReplayFrame | None:
        try:
            color = image_to_rgb(color_message)
            depth = depth_to_metres(image_to_array(depth_message), depth_message.encoding)
            if depth.shape != color.shape[:2]:
                raise InvalidInputError(f"depth {depth.shape[1]}x{depth.shape[0]} is not registered to the "
                                        f"{color.shape[1]}x{color.shape[0]} colour image")
        except InvalidInputError as error:
            self._skip("frame that does not convert", f"frame {index}: {error}")
            return None
        return ReplayFrame(index, plan.color_ns / 1e9, color, depth, plan.intrinsics, plan.camera_to_world,
                           detections=plan.detections)

    def _skip(self, reason: str, detail: str = "") -> None:
        """Count a skipped frame or message; say the first of each kind (a bag may repeat it often)."""
        self.skipped[reason] += 1
        if reason not in self._said:
            self._said.add(reason)
            print(f"bag: skipped a {reason}" + (f": {detail}" if detail else "") + " (said once; counted in the "
                  "summary)", file=sys.stderr)


class _TfLookup:
    """Camera poses from a bag's TF, through tf2's own buffer (tf2_ros, where it is installed)."""

    def __init__(self, transforms: list[tuple[Any, bool]], world_frame: str) -> None:
        try:
            from rclpy.duration import Duration
            from rclpy.time import Time
            from tf2_ros import Buffer
        except ImportError as error:
            raise ConfigurationError(
                f"the bag gives the camera pose through TF, which needs tf2_ros ({error}); on a robot it is "
                "installed; here, SAILOR_UPSTREAM builds it. Or name a pose topic with --pose-topic") from None
        self._time = Time
        stamps = [stamp_to_seconds(transform.header.stamp) for transform, static in transforms if not static]
        span = (max(stamps) - min(stamps)) if stamps else 0.0
        self._buffer = Buffer(cache_time=Duration(seconds=span + 60.0))
        for transform, static in transforms:
            if static:
                self._buffer.set_transform_static(transform, "bag")
            else:
                self._buffer.set_transform(transform, "bag")
        self._world_frame = world_frame

    def pose(self, camera_frame: str, stamp_ns: int) -> Pose:
        import tf2_ros

        try:
            transform = self._buffer.lookup_transform(
                self._world_frame, camera_frame, self._time(nanoseconds=stamp_ns))
        except (tf2_ros.LookupException, tf2_ros.ConnectivityException, tf2_ros.ExtrapolationException) as error:
            raise InvalidInputError(f"{self._world_frame} <- {camera_frame}: {error}") from None
        return transform_to_pose(transform)


def _stamp_ns(message: Any) -> int:
    return int(message.header.stamp.sec) * 1_000_000_000 + int(message.header.stamp.nanosec)


def _nearest(sorted_stamps: list[int], stamp: int, slop_ns: int) -> int | None:
    """The stamp of ``sorted_stamps`` nearest ``stamp``, if within ``slop_ns``."""
    position = bisect.bisect_left(sorted_stamps, stamp)
    candidates = sorted_stamps[max(0, position - 1):position + 1]
    if not candidates:
        return None
    best = min(candidates, key=lambda candidate: abs(candidate - stamp))
    return best if abs(best - stamp) <= slop_ns else None
