"""Stand-in processes for fault and network tests: a camera that publishes percepts, and an observer.

``python split_roles.py camera --rate 10 --objects 3 [--appear-every 2] [--duration 20]``
    plays the perceptual layer: camera info, camera pose and a PerceptArray per frame, all with
    the same stamp (the wall clock), for ``objects`` objects in front of a camera 1 m above the
    map origin looking along +x (rgbd_player's default pose). It starts once a node subscribes to
    its percepts (or after ``--wait-for-subscriber`` seconds). Object k first appears at
    ``k * appear_every`` seconds, so anchors keep being made while the test kills things.
    On exit (duration over, SIGINT or SIGTERM) it prints ``{"published": N, ...}`` as JSON.

``python split_roles.py observe --knowledge-base /ns --expect-anchors 3 [--timeout 60] [--duration 0]``
    listens to the anchoring node's anchors and events and, when asked, reads the knowledge base;
    it exits once every expected anchor exists and the knowledge base holds its object and
    ``object_at`` fact (or after ``duration`` seconds of measuring, or at the timeout), printing
    one JSON line: the anchors, the frames anchored with their percept-to-anchor latencies, and
    the knowledge base's objects and facts.

Both read the ROS environment they are started with, so they run on loopback in the test run's
domain or inside a namespace of :mod:`network_split`.
"""

from __future__ import annotations

import argparse
import json
import signal
import statistics
import sys
import time
from typing import Any

import numpy as np

OBJECT_CLASSES = ("cup", "book", "bottle", "bowl")
# Distinct places in front of the camera, at least 1 m apart: x ahead, y to the left, z up (map).
OBJECT_PLACES = tuple((x, y, 0.8) for x in (2.5, 3.5, 4.5) for y in (0.0, 1.0, -1.0))
CAMERA_POSE = (0.0, 0.0, 1.0, -0.5, 0.5, -0.5, 0.5)  # rgbd_player's default: x, y, z, qx, qy, qz, qw
WORLD_FRAME = "map"


def object_list(count: int) -> list[tuple[str, tuple[float, float, float]]]:
    """The ``count`` objects the camera stand-in shows, in the order they appear."""
    if not 0 < count <= len(OBJECT_PLACES):
        raise ValueError(f"between 1 and {len(OBJECT_PLACES)} objects, got {count}")
    return [(OBJECT_CLASSES[k % len(OBJECT_CLASSES)], OBJECT_PLACES[k]) for k in range(count)]


class StopFlag:
    """Set by SIGINT or SIGTERM; the roles poll it between frames."""

    def __init__(self) -> None:
        self.set = False
        for number in (signal.SIGINT, signal.SIGTERM):
            signal.signal(number, self._stop)

    def _stop(self, *_: object) -> None:
        self.set = True


def run_camera(arguments: argparse.Namespace) -> dict[str, Any]:
    import rclpy
    from geometry_msgs.msg import PoseStamped
    from rclpy.signals import SignalHandlerOptions
    from sensor_msgs.msg import CameraInfo
    from std_msgs.msg import Header

    from merlin2_sailor.contract.percept import BoundingBox2D, Percept
    from merlin2_sailor.ros.conversions import camera_info_message, percepts_to_message, seconds_to_stamp
    from merlin2_sailor.ros.qos import SENSOR_DATA
    from merlin2_sailor_interfaces.msg import PerceptArray

    stop = StopFlag()
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)  # StopFlag handles the signals
    node = rclpy.create_node("camera_stand_in")
    info_publisher = node.create_publisher(CameraInfo, "color/camera_info", SENSOR_DATA)
    pose_publisher = node.create_publisher(PoseStamped, "camera_pose", SENSOR_DATA)
    percept_publisher = node.create_publisher(PerceptArray, "percepts", SENSOR_DATA)
    objects = object_list(arguments.objects)
    crop = np.full((arguments.crop_pixels, arguments.crop_pixels, 3), 90, np.uint8)
    period = 1.0 / arguments.rate
    waited = time.monotonic() + arguments.wait_for_subscriber
    while not stop.set and percept_publisher.get_subscription_count() == 0 and time.monotonic() < waited:
        rclpy.spin_once(node, timeout_sec=0.05)  # frames before discovery would be lost, not measured
    started = time.monotonic()
    deadline = started + arguments.duration if arguments.duration > 0 else float("inf")
    published, first_stamp, last_stamp = 0, None, None
    next_frame = started
    try:
        while not stop.set and time.monotonic() < deadline:
            rclpy.spin_once(node, timeout_sec=max(0.0, next_frame - time.monotonic()))
            if time.monotonic() < next_frame:
                continue
            next_frame += period
            elapsed = time.monotonic() - started
            shown = [item for k, item in enumerate(objects) if elapsed >= k * arguments.appear_every]
            stamp = time.time()
            header = Header(stamp=seconds_to_stamp(stamp), frame_id="camera_color_optical_frame")
            info_publisher.publish(camera_info_message(640, 480, 500.0, 500.0, 320.0, 240.0, header))
            pose = PoseStamped(header=Header(stamp=header.stamp, frame_id=WORLD_FRAME))
            position, orientation = pose.pose.position, pose.pose.orientation
            position.x, position.y, position.z, orientation.x, orientation.y, orientation.z, orientation.w = (
                CAMERA_POSE)
            pose_publisher.publish(pose)
            percepts = [Percept(class_name=name, score=0.9, box=BoundingBox2D(320, 240, 40, 40),
                                position=np.array(place), size=np.array([0.1, 0.1, 0.12]), stamp=stamp,
                                crop=crop, frame_id=WORLD_FRAME)
                        for name, place in shown]
            percept_publisher.publish(percepts_to_message(percepts, Header(stamp=header.stamp, frame_id=WORLD_FRAME)))
            published += 1
            first_stamp = stamp if first_stamp is None else first_stamp
            last_stamp = stamp
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return {"role": "camera", "published": published, "first_stamp": first_stamp, "last_stamp": last_stamp,
            "rate": arguments.rate, "objects": arguments.objects}


def run_observer(arguments: argparse.Namespace) -> dict[str, Any]:
    import rclpy
    from rclpy.qos import QoSProfile
    from rclpy.signals import SignalHandlerOptions

    from merlin2_sailor.errors import KnowledgeError
    from merlin2_sailor.ros.conversions import stamp_to_seconds
    from merlin2_sailor.ros.qos import EVENTS, LATCHED
    from merlin2_sailor.ros.stores import open_store
    from merlin2_sailor_interfaces.msg import AnchorArray, AnchorEvent, AnchorEventArray

    stop = StopFlag()
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("split_observer")
    anchors: dict[str, str] = {}
    frame_latencies: dict[float, float] = {}  # percept stamp -> seconds until its events arrived here
    started_wall = time.time()

    def on_anchors(message: AnchorArray) -> None:
        anchors.clear()
        anchors.update({anchor.symbol: anchor.class_name for anchor in message.anchors})

    def on_events(message: AnchorEventArray) -> None:
        received = time.time()
        for event in message.events:
            if event.kind in (AnchorEvent.KIND_ACQUIRED, AnchorEvent.KIND_REACQUIRED):
                stamp = stamp_to_seconds(event.stamp)
                if stamp >= started_wall and stamp not in frame_latencies:
                    frame_latencies[stamp] = received - stamp

    node.create_subscription(AnchorArray, "anchors", on_anchors, LATCHED)
    node.create_subscription(AnchorEventArray, "anchor_events", on_events,
                             QoSProfile(depth=100, reliability=EVENTS.reliability))
    store = open_store(f"ros://{arguments.knowledge_base}") if arguments.knowledge_base else None
    objects: list[str] = []
    facts: list[list[Any]] = []
    knowledge_error = ""
    started = time.monotonic()
    measuring_until = started + arguments.duration if arguments.duration > 0 else None
    next_check = started

    def knowledge_complete() -> bool:
        nonlocal objects, facts, knowledge_error
        if store is None:
            return True
        try:
            objects = sorted(item.name for item in store.objects.get_all())
            facts = sorted([fact.predicate, *fact.objects] for fact in store.propositions.get_all())
            knowledge_error = ""
        except KnowledgeError as error:
            knowledge_error = str(error)
            return False
        located = {fact[1] for fact in facts if fact[0] == "object_at"}
        return set(anchors) <= set(objects) and set(anchors) <= located

    done = False
    try:
        while not stop.set and time.monotonic() - started < arguments.timeout:
            rclpy.spin_once(node, timeout_sec=0.05)
            if measuring_until is not None:
                if time.monotonic() >= measuring_until:
                    knowledge_complete()
                    done = True
                    break
                continue
            if time.monotonic() >= next_check and len(anchors) >= arguments.expect_anchors:
                next_check = time.monotonic() + 0.5
                if knowledge_complete():
                    done = True
                    break
    finally:
        if store is not None:
            store.close()
        node.destroy_node()
        rclpy.try_shutdown()
    latencies = sorted(frame_latencies.values())
    window = max(time.monotonic() - started, 1e-9)
    return {
        "role": "observer", "complete": done, "anchors": anchors, "objects": objects, "facts": facts,
        "knowledge_error": knowledge_error, "frames_anchored": len(latencies), "seconds": window,
        "frames_per_second": len(latencies) / window,
        "latency_ms": {
            "count": len(latencies),
            "median": 1000.0 * statistics.median(latencies) if latencies else None,
            "p95": 1000.0 * latencies[int(0.95 * (len(latencies) - 1))] if latencies else None,
            "max": 1000.0 * latencies[-1] if latencies else None,
        },
        "latencies_ms": [round(1000.0 * value, 2) for value in latencies] if arguments.keep_samples else [],
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    roles = parser.add_subparsers(dest="role", required=True)
    camera = roles.add_parser("camera")
    camera.add_argument("--rate", type=float, default=10.0, help="frames per second")
    camera.add_argument("--objects", type=int, default=2)
    camera.add_argument("--appear-every", type=float, default=0.0, help="seconds between two objects' first frames")
    camera.add_argument("--crop-pixels", type=int, default=8, help="side of each percept's square RGB crop")
    camera.add_argument("--duration", type=float, default=0.0, help="seconds to run; 0 until SIGINT")
    camera.add_argument("--wait-for-subscriber", type=float, default=30.0,
                        help="seconds to wait for a percepts subscriber before the first frame")
    observer = roles.add_parser("observe")
    observer.add_argument("--knowledge-base", default="", help="namespace of the knowledge_base node")
    observer.add_argument("--expect-anchors", type=int, default=1)
    observer.add_argument("--timeout", type=float, default=60.0)
    observer.add_argument("--duration", type=float, default=0.0,
                          help="measure for this many seconds instead of waiting for the anchors")
    observer.add_argument("--keep-samples", action="store_true", help="print every latency sample")
    arguments = parser.parse_args(argv)
    summary = run_camera(arguments) if arguments.role == "camera" else run_observer(arguments)
    print(json.dumps(summary), flush=True)
    return 0 if summary.get("complete", True) else 1


if __name__ == "__main__":
    sys.exit(main())
