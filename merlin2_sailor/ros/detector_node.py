"""detector: colour images in, merlin2_sailor_interfaces/DetectionArray out, one per processed frame.

The backend is a plug-in of :mod:`merlin2_sailor.perception.detector` chosen by the ``backend``
parameter (``ssd_mobilenet``, offline and the default, or ``ultralytics`` with a local weights
file), or ``external``: another node detects (a YOLO ROS 2 node, a simulator's ground truth) and
this one only validates its DetectionArray and republishes it under the project's topic name.

Scheduling: detection runs on a worker thread fed by a one-frame mailbox, so the newest frame
always wins. A frame that arrives while the detector is busy replaces the waiting one, and the
replaced frame is counted as dropped; nothing queues without bound, and the latency of a slow
backend never grows. Each DetectionArray carries the header of its image (stamp and optical
frame), which is how the percept generator pairs it with the depth and pose of the same instant.

Tracking is not done here but in the percept generator, next to the only consumer of the ids
(see :mod:`merlin2_sailor.ros.percept_node`).
"""

from __future__ import annotations

import threading
import time
import traceback
from collections.abc import Sequence
from typing import Any

from rclpy.node import Node
from sensor_msgs.msg import Image

from merlin2_sailor.diagnostics.topic_statistics import TopicStatistics
from merlin2_sailor.errors import ConfigurationError, InvalidInputError, SailorError
from merlin2_sailor.inference.settings import DETECTOR_PRECISIONS, DEVICES, RUNTIMES, InferenceSettings
from merlin2_sailor.perception.detector import Detector
from merlin2_sailor.perception.detector_registry import DETECTOR_BACKENDS, create_detector
from merlin2_sailor.perception.ssd_mobilenet import SsdMobileNetConfig
from merlin2_sailor.ros.conversions import (
    detection_from_message,
    detections_to_message,
    image_to_rgb,
    stamp_to_seconds,
)
from merlin2_sailor.ros.newest_frame_mailbox import NewestFrameMailbox
from merlin2_sailor.ros.node_runner import run_node
from merlin2_sailor.ros.parameters import declare_parameter
from merlin2_sailor.ros.qos import SENSOR_DATA
from merlin2_sailor_interfaces.msg import DetectionArray

NODE_NAME = "detector"
EXTERNAL_BACKEND = "external"
BACKENDS = tuple(sorted((*DETECTOR_BACKENDS, EXTERNAL_BACKEND)))
IMAGE_TOPIC = "color/image_raw"
DETECTIONS_TOPIC = "detections"
EXTERNAL_DETECTIONS_TOPIC = "detections_in"
WARNING_PERIOD_SECONDS = 5.0  # bad input is logged at most this often, whatever the camera rate
#: Masks are rasterised at the size they claim: one claiming more pixels than any camera image is
#: refused unread (2**31 x 2**31 raised MemoryError and killed the node; less would fill the memory).
MAXIMUM_MASK_PIXELS = 8192 * 8192


class DetectorNode(Node):
    def __init__(self) -> None:
        super().__init__(NODE_NAME)
        backend = declare_parameter(
            self, "backend", "ssd_mobilenet",
            f"Detector backend: {', '.join(BACKENDS)} (republish another node's DetectionArray from "
            f"'{EXTERNAL_DETECTIONS_TOPIC}').",
        )
        score_threshold = declare_parameter(
            self, "score_threshold", 0.5, "Detections below this confidence are discarded (not for external).",
            minimum=0.0, maximum=1.0,
        )
        classes = [name for name in declare_parameter(
            self, "classes", [""], "Class names to keep (COCO spelling, e.g. 'cup'); [''] keeps all (ssd_mobilenet).",
        ) if name]
        weights = declare_parameter(
            self, "weights", "", "Local YOLO weights file for the ultralytics backend; never downloaded.",
        )
        device = declare_parameter(self, "device", "cpu", "Torch device of the ultralytics backend ('cpu', 'cuda:0').")
        report_period = declare_parameter(
            self, "report_period", 10.0, "Seconds between two statistics log lines.", minimum=0.5, maximum=3600.0,
        )
        defaults = SsdMobileNetConfig().inference
        inference = InferenceSettings(
            runtime=declare_parameter(
                self, "inference_runtime", defaults.runtime,
                f"ssd_mobilenet's runtime: {' or '.join(RUNTIMES)} (OpenCV DNN)."),
            device=declare_parameter(
                self, "inference_device", defaults.device,
                f"OpenVINO device: {', '.join(DEVICES)}; one this machine lacks falls back to the CPU."),
            threads=declare_parameter(
                self, "inference_threads", defaults.threads, "Inference threads, 0 for every core.",
                minimum=0, maximum=256),
            precision=declare_parameter(
                self, "inference_precision", defaults.precision,
                f"OpenVINO precision: {', '.join(DETECTOR_PRECISIONS)} (int8: quantised once, about twice auto's "
                "speed; auto: the device's fastest float, bfloat16 where it has it)."),
        )

        self._publisher = self.create_publisher(DetectionArray, DETECTIONS_TOPIC, SENSOR_DATA)
        self._report_period = report_period
        self._statistics = TopicStatistics(window_seconds=report_period)
        self._statistics_lock = threading.Lock()
        self._detection_seconds = 0.0  # time spent in detect() since the last report ...
        self._detection_frames = 0  # ... over this many frames
        self._invalid_detections = 0
        self._mailbox = NewestFrameMailbox()
        self._worker: threading.Thread | None = None

        if backend == EXTERNAL_BACKEND:
            self.create_subscription(DetectionArray, EXTERNAL_DETECTIONS_TOPIC, self._republish, SENSOR_DATA)
            source = f"republishing '{self.resolve_topic_name(EXTERNAL_DETECTIONS_TOPIC)}'"
        else:
            self._detector = self._build_detector(backend, score_threshold, classes, weights, device, inference)
            self.create_subscription(Image, IMAGE_TOPIC, self._mailbox.put, SENSOR_DATA)
            self._worker = threading.Thread(target=self._detect_frames, name="detector", daemon=True)
            self._worker.start()
            runtime = (f" ({inference.describe()}: {self._detector.threads} threads)"
                       if backend == "ssd_mobilenet" else "")
            source = f"{backend}{runtime} on '{self.resolve_topic_name(IMAGE_TOPIC)}'"
        self.create_timer(report_period, self._report)
        self.get_logger().info(f"{source} -> '{self.resolve_topic_name(DETECTIONS_TOPIC)}'")

    def _build_detector(
        self, backend: str, score_threshold: float, classes: list[str], weights: str, device: str,
        inference: InferenceSettings,
    ) -> Detector:
        if backend not in DETECTOR_BACKENDS:
            raise ConfigurationError(f"backend must be one of {', '.join(BACKENDS)}, got '{backend}'")
        if backend == "ultralytics":
            if not weights:
                raise ConfigurationError(
                    "backend 'ultralytics' needs the parameter 'weights': a local YOLO weights file "
                    "(it never downloads one); or use backend 'ssd_mobilenet'"
                )
            if classes:
                raise ConfigurationError("the 'classes' filter is supported by the ssd_mobilenet backend only")
            options: dict[str, Any] = {"weights_path": weights, "score_threshold": score_threshold, "device": device}
        else:
            options = {"score_threshold": score_threshold, "classes": tuple(classes), "inference": inference}
        return create_detector(backend, options, self.get_logger().warning)

    def _detect_frames(self) -> None:
        """Worker thread: detect on the newest waiting frame, publish, repeat until closed."""
        while (message := self._mailbox.take()) is not None:
            try:
                image = image_to_rgb(message)
                started = time.perf_counter()
                detections = self._detector.detect(image)
                elapsed = time.perf_counter() - started
                self._publisher.publish(detections_to_message(detections, message.header))
            except SailorError as error:
                self.get_logger().warning(f"image dropped: {error}", throttle_duration_sec=WARNING_PERIOD_SECONDS)
                continue
            except Exception:  # a bug on one frame must not silently end detection for the node's life
                if not self.context.ok():
                    return  # shutting down: the publisher went away under us
                self.get_logger().error(
                    f"detection failed:\n{traceback.format_exc()}", throttle_duration_sec=WARNING_PERIOD_SECONDS
                )
                continue
            with self._statistics_lock:
                self._statistics.record(self._now(), stamp_to_seconds(message.header.stamp))
                self._detection_seconds += elapsed
                self._detection_frames += 1

    def _republish(self, message: DetectionArray) -> None:
        valid = []
        for detection in message.detections:
            try:
                if detection.mask.data and detection.mask.height * detection.mask.width > MAXIMUM_MASK_PIXELS:
                    raise InvalidInputError(
                        f"detection '{detection.class_name}' has a mask of {detection.mask.width}x"
                        f"{detection.mask.height} pixels, more than the {MAXIMUM_MASK_PIXELS} of any camera image")
                detection_from_message(detection)
            except InvalidInputError as error:
                self._invalid_detections += 1
                self.get_logger().warning(
                    f"external detection dropped: {error}", throttle_duration_sec=WARNING_PERIOD_SECONDS
                )
                continue
            valid.append(detection)
        self._publisher.publish(DetectionArray(header=message.header, detections=valid))
        with self._statistics_lock:
            self._statistics.record(self._now(), stamp_to_seconds(message.header.stamp))

    def _report(self) -> None:
        with self._statistics_lock:
            report = self._statistics.report(self._now())
            detection_seconds, self._detection_seconds = self._detection_seconds, 0.0
            detection_frames, self._detection_frames = self._detection_frames, 0
        if report.total_messages == 0:
            return
        parts = [f"{report.messages} frames in the last {self._report_period:g} s ({report.rate_hz:.1f} Hz)"]
        if detection_frames:
            parts.append(f"{1000.0 * detection_seconds / detection_frames:.0f} ms/frame detecting")
        if report.mean_age_seconds is not None:
            parts.append(f"image-to-publish latency {1000.0 * report.mean_age_seconds:.0f} ms")
        if self._worker is not None:
            parts.append(f"{self._mailbox.dropped} frames dropped while busy since start")
        else:
            parts.append(f"{self._invalid_detections} invalid detections dropped since start")
        self.get_logger().info(", ".join(parts))

    def _now(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    def destroy_node(self) -> None:
        # Stop the worker before the publisher it uses is destroyed.
        self._mailbox.close()
        if self._worker is not None:
            self._worker.join(timeout=10.0)
        super().destroy_node()


def main(argv: Sequence[str] | None = None) -> int:
    return run_node(DetectorNode, argv)


if __name__ == "__main__":
    raise SystemExit(main())
