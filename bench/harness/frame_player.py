"""The pipeline benchmarks' camera: plays a synthetic RGB-D scene into the real nodes, on a schedule.

Run as a process of the benchmark's graph (``sailor bench`` starts it through the launcher)::

    python bench/harness/frame_player.py --objects 10 --phase "15 Hz:15:60:3" --output frames.json \
        --ros-args -r __ns:=/bench

Per frame it publishes, all with one header stamp (the wall-clock time of publication): the
colour image (rgb8), the registered depth (16UC1, mm), the camera info, the camera pose in
``map`` and the ground-truth DetectionArray (so the detector is left out of the measurement).
It first waits until the percept generator, the anchoring node and the benchmark's probe are all
in the graph, then plays slow frames, not measured, until the anchoring node has answered one
(its networks loaded and compiled). A phase ``LABEL:RATE:SECONDS:SETTLE`` plays RATE frames per second for SECONDS,
the first SETTLE seconds of which are not measured (anchors being acquired, the tracker's rate
estimate). The schedule is absolute: a tick this process is too late for is skipped and
counted, never bunched up. At the end it writes every frame's stamp to ``--output`` (JSON), waits
``--drain`` seconds for the last frames to come through, and exits 0.
"""

# ruff: noqa: E402 - bench/ goes on sys.path before the harness is imported
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import argparse
import json
import signal
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import rclpy
from builtin_interfaces.msg import Time
from geometry_msgs.msg import PoseStamped
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from rclpy.utilities import remove_ros_args
from sensor_msgs.msg import CameraInfo, Image
from std_msgs.msg import Header

from harness.scene import Scene, detections_of, load_object_photos, make_scene
from merlin2_sailor.ros.conversions import array_to_image, camera_info_message, detections_to_message, pose_to_message
from merlin2_sailor.ros.qos import ANY_PUBLISHER, SENSOR_DATA
from merlin2_sailor_interfaces.msg import AnchorArray, DetectionArray

OPTICAL_FRAME = "camera_color_optical_frame"
WORLD_FRAME = "map"
GRAPH_TIMEOUT_SECONDS = 60.0
#: Frames per second, and the longest wait, of the warm-up before the phases (see :func:`warm_up`).
WARM_UP_RATE_HZ = 2.0
WARM_UP_TIMEOUT_SECONDS = 60.0


@dataclass(frozen=True)
class Phase:
    label: str
    rate_hz: float
    seconds: float
    settle_seconds: float

    @classmethod
    def parse(cls, text: str) -> Phase:
        label, rate, seconds, settle = text.rsplit(":", 3)
        phase = cls(label, float(rate), float(seconds), float(settle))
        if phase.rate_hz <= 0.0 or phase.seconds <= 0.0 or not 0.0 <= phase.settle_seconds < phase.seconds:
            raise argparse.ArgumentTypeError(f"bad phase {text!r}: need rate > 0, seconds > 0, 0 <= settle < seconds")
        return phase

    def argument(self) -> str:
        return f"{self.label}:{self.rate_hz:g}:{self.seconds:g}:{self.settle_seconds:g}"


class FramePlayer:
    """Publishes one scene's messages with a fresh stamp each frame (messages built once)."""

    def __init__(self, node: Node, scene: Scene, seed: int = 1, with_detector: bool = False) -> None:
        self._node, self._scene, self._with_detector = node, scene, with_detector
        self._rng = np.random.default_rng(seed)
        self.info = node.create_publisher(CameraInfo, "color/camera_info", SENSOR_DATA)
        self.pose = node.create_publisher(PoseStamped, "camera_pose", SENSOR_DATA)
        self.depth = node.create_publisher(Image, "depth/image_raw", SENSOR_DATA)
        self.image = node.create_publisher(Image, "color/image_raw", SENSOR_DATA)
        self.detections = node.create_publisher(DetectionArray, "detections", SENSOR_DATA)
        intrinsics = scene.intrinsics
        self._info_message = camera_info_message(intrinsics.width, intrinsics.height, intrinsics.fx, intrinsics.fy,
                                                 intrinsics.cx, intrinsics.cy)
        self._pose_message = PoseStamped(pose=pose_to_message(scene.camera_to_world))
        self._depth_message = array_to_image(scene.depth_millimetres, "16UC1")
        self._image_message = array_to_image(scene.color, "rgb8")

    def publish(self, stamp_ns: int) -> None:
        stamp = Time(sec=stamp_ns // 1_000_000_000, nanosec=stamp_ns % 1_000_000_000)
        optical = Header(stamp=stamp, frame_id=OPTICAL_FRAME)
        self._info_message.header = optical
        self._pose_message.header = Header(stamp=stamp, frame_id=WORLD_FRAME)
        self._depth_message.header = optical
        self._image_message.header = optical
        self.info.publish(self._info_message)
        self.pose.publish(self._pose_message)
        self.depth.publish(self._depth_message)
        self.image.publish(self._image_message)
        if not self._with_detector:  # else the detector node finds them in the image
            self.detections.publish(detections_to_message(detections_of(self._scene, self._rng), optical))

    def graph_ready(self, percepts_subscribers: int) -> bool:
        """Everyone listening: the percept generator, the anchoring node and the benchmark's probe."""
        node = self._node
        publishers = (self.info, self.pose, self.depth, self.image)
        if not self._with_detector:
            publishers += (self.detections,)
        return (all(p.get_subscription_count() > 0 for p in publishers)
                and node.count_subscribers(node.resolve_topic_name("percepts")) >= percepts_subscribers
                and node.count_publishers(node.resolve_topic_name("anchors")) >= 1
                and node.count_subscribers(node.resolve_topic_name("anchors")) >= 1)


def warm_up(node: Node, player: FramePlayer, stop: threading.Event) -> bool:
    """Slow frames, never measured, until the anchoring node has answered one (True), or
    :data:`WARM_UP_TIMEOUT_SECONDS` passed (False).

    Why: the anchoring node's first frames pay for loading and compiling its networks. On a busy
    machine that once took longer than a whole phase, and the phase measured the start, not the
    load (the test suite's short form, 5 December 2026: no frame of the 9-s 30 Hz phase anchored
    while the tests' other worker ran MERLIN2). The phases' frames are what the figures are of.
    """
    answered = threading.Event()
    subscription = node.create_subscription(AnchorArray, "anchors", lambda _message: answered.set(), ANY_PUBLISHER)
    deadline = time.monotonic() + WARM_UP_TIMEOUT_SECONDS
    next_frame = time.monotonic()
    try:
        while not (answered.is_set() or stop.is_set()) and time.monotonic() < deadline:
            if time.monotonic() >= next_frame:
                player.publish(time.time_ns())
                next_frame += 1.0 / WARM_UP_RATE_HZ
            rclpy.spin_once(node, timeout_sec=0.05)
    finally:
        node.destroy_subscription(subscription)
    return answered.is_set()


def play(player: FramePlayer, phases: Sequence[Phase], stop: threading.Event) -> dict:
    frames: list[list[int]] = []  # [stamp_ns, phase index, measured (0/1)]
    records = []
    publish_seconds: list[float] = []
    for index, phase in enumerate(phases):
        period = 1.0 / phase.rate_hz
        started_ns, started = time.time_ns(), time.monotonic()
        tick, end, late = started, started + phase.seconds, 0
        print(f"phase {phase.label!r}: {phase.rate_hz:g} Hz for {phase.seconds:g} s", flush=True)
        while not stop.is_set():
            now = time.monotonic()
            if tick >= end:
                break
            if tick > now:
                stop.wait(tick - now)
                continue
            stamp_ns = time.time_ns()
            player.publish(stamp_ns)
            publish_seconds.append(time.monotonic() - now)
            frames.append([stamp_ns, index, int(now - started >= phase.settle_seconds)])
            tick += period
            behind = time.monotonic() - tick
            if behind > period:  # too late for whole ticks: skip them rather than bunch frames up
                skipped = int(behind // period)
                tick += skipped * period
                late += skipped
        records.append({**phase.__dict__, "started_ns": started_ns, "ended_ns": time.time_ns(), "late_ticks": late})
    publish_ms = np.array(publish_seconds) * 1e3 if publish_seconds else np.zeros(1)
    return {"phases": records, "frames": frames,
            "publish_ms": {"mean": float(publish_ms.mean()), "max": float(publish_ms.max())}}


def main(argv: Sequence[str] | None = None) -> int:
    arguments = list(sys.argv if argv is None else argv)
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--objects", type=int, required=True)
    parser.add_argument("--phase", type=Phase.parse, action="append", required=True, dest="phases")
    parser.add_argument("--output", type=Path, required=True)
    parser.add_argument("--drain", type=float, default=1.5, help="seconds to wait after the last frame")
    parser.add_argument("--percepts-subscribers", type=int, default=2,
                        help="subscribers of 'percepts' to wait for (anchoring + the benchmark's probe)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--detector", action="store_true",
                        help="publish no detections (the detector node finds them): objects show real photos")
    options = parser.parse_args(remove_ros_args(arguments)[1:])

    stop = threading.Event()
    for number in (signal.SIGINT, signal.SIGTERM):
        signal.signal(number, lambda *_: stop.set())
    rclpy.init(args=arguments, signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("frame_player")
    try:
        photos = load_object_photos(options.objects) if options.detector else []
        scene = make_scene(options.objects, options.seed, photos=photos)
        player = FramePlayer(node, scene, with_detector=options.detector)
        deadline = time.monotonic() + GRAPH_TIMEOUT_SECONDS
        while not player.graph_ready(options.percepts_subscribers):
            if stop.is_set():
                return 0
            if time.monotonic() > deadline:
                print(f"the graph was not ready after {GRAPH_TIMEOUT_SECONDS:.0f} s: percept_generator, anchoring "
                      "and the probe must all be running", file=sys.stderr, flush=True)
                return 3
            time.sleep(0.1)
        time.sleep(0.5)  # let the nodes' own connections (percepts -> anchoring) settle too
        if not warm_up(node, player, stop):
            print(f"the anchoring node answered no frame in {WARM_UP_TIMEOUT_SECONDS:.0f} s of warm-up; playing anyway",
                  file=sys.stderr, flush=True)
        record = play(player, options.phases, stop)
        record["objects"] = options.objects
        options.output.write_text(json.dumps(record))
        print(f"played {len(record['frames'])} frames; waiting {options.drain:g} s for the last ones", flush=True)
        stop.wait(options.drain)
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
