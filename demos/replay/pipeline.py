"""The perceptual and anchoring layers over one frame at a time, with the core classes, no ROS.

detector -> ByteTrack -> percept generator -> :class:`~merlin2_sailor.anchoring.anchoring.Anchoring`,
the same chain the ``detector``, ``percept_generator`` and ``anchoring`` nodes run, minus the
messages. The detector and the tracker are anything with the core's verbs (``detect(image)``,
``update(detections, stamp)``), so a test can hand in a scripted detector.
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from merlin2_sailor.anchoring.anchoring import Anchoring, AnchoringResult
from merlin2_sailor.anchoring.service import AnchoringService
from merlin2_sailor.anchoring.visibility import CameraView
from merlin2_sailor.contract.percept import Percept
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor.perception.detector_registry import DETECTOR_BACKENDS, create_detector
from merlin2_sailor.perception.percept_generator import PerceptGenerator
from merlin2_sailor_demos.replay.source import ReplayFrame, ReplaySource

#: Short names accepted by ``--detector`` besides the backends' own.
DETECTOR_ALIASES = {"ssd": "ssd_mobilenet", "yolo": "ultralytics"}


class FrameDetector(Protocol):
    def detect(self, image_rgb: np.ndarray) -> list[Detection]: ...


class FrameTracker(Protocol):
    def update(self, detections: Sequence[Detection], stamp: float | None = None) -> list[Detection]: ...


@dataclass(frozen=True, slots=True, eq=False)
class BoxOutcome:
    """One detection of a frame: the anchor symbol it was given, or why it made no percept."""

    detection: Detection
    symbol: str = ""
    drop_reason: str = ""


@dataclass(frozen=True, slots=True, eq=False)
class FrameOutcome:
    """What one frame produced; ``seconds`` holds the time of each stage."""

    frame: ReplayFrame
    boxes: tuple[BoxOutcome, ...]
    percepts: tuple[Percept, ...]
    result: AnchoringResult
    depth: np.ndarray
    seconds: dict[str, float] = field(default_factory=dict)


class ReplayPipeline:
    """``step(frame)`` runs one frame through every stage and returns a :class:`FrameOutcome`."""

    def __init__(
        self,
        source: ReplaySource,
        detector: FrameDetector | None,
        tracker: FrameTracker | None,
        anchoring: Anchoring | None = None,
        percept_generator: PerceptGenerator | None = None,
        lock: threading.Lock | None = None,
    ) -> None:
        """``lock``: held while a frame is anchored, where another thread reads the anchors (the
        anchoring service's persistence worker, when the replay writes a knowledge base)."""
        self.source = source
        self.detector = detector
        self.tracker = tracker
        # `is None`, not `or`: an Anchoring with no anchors yet has length 0 and is falsy.
        self.anchoring = AnchoringService(source.anchoring_settings()).anchoring if anchoring is None else anchoring
        self.percept_generator = (
            PerceptGenerator(source.percept_config()) if percept_generator is None else percept_generator
        )
        self._lock = lock if lock is not None else contextlib.nullcontext()

    def step(self, frame: ReplayFrame) -> FrameOutcome:
        seconds: dict[str, float] = {}
        started = time.perf_counter()
        if frame.detections is not None:  # recorded with the frame: what the robot's detector found
            detections = list(frame.detections)
        elif self.detector is None:
            raise ConfigurationError(f"frame {frame.index} of '{self.source.name}' has no recorded detections "
                                     "and the replay has no detector")
        else:
            detections = list(self.detector.detect(frame.color))
        seconds["detect"] = _lap(started)
        started = time.perf_counter()
        if self.tracker is not None:
            detections = list(self.tracker.update(detections, frame.stamp))
        seconds["track"] = _lap(started)
        started = time.perf_counter()
        depth = self.source.depth_for(frame, detections)
        batch = self.percept_generator.generate(
            detections, frame.color, depth, frame.intrinsics, frame.camera_to_world, frame.stamp
        )
        seconds["percepts"] = _lap(started)
        started = time.perf_counter()
        view = CameraView(frame.intrinsics, frame.camera_to_world, depth)
        with self._lock:
            result = self.anchoring.process(batch.percepts, view, frame.stamp)
        seconds["anchoring"] = _lap(started)

        # The generator keeps detection order and lists each dropped detection itself, so the
        # percepts line up with the detections that were not dropped.
        dropped = {id(drop.detection): drop.reason.value for drop in batch.dropped}
        symbols = iter(result.percept_symbols)
        boxes = tuple(
            BoxOutcome(detection, drop_reason=dropped[id(detection)]) if id(detection) in dropped
            else BoxOutcome(detection, symbol=next(symbols))
            for detection in detections
        )
        return FrameOutcome(frame, boxes, batch.percepts, result, depth, seconds)


def _lap(started: float) -> float:
    return time.perf_counter() - started


def create_replay_detector(name: str, score_threshold: float | None = None) -> FrameDetector:
    """The detector backend ``name`` (or an alias: ssd, yolo), with its score threshold if given."""
    backend = DETECTOR_ALIASES.get(name, name)
    if backend not in DETECTOR_BACKENDS:
        known = sorted(set(DETECTOR_BACKENDS) | set(DETECTOR_ALIASES))
        raise ConfigurationError(f"unknown detector '{name}'; choose one of {', '.join(known)}")
    options: dict[str, Any] = {} if score_threshold is None else {"score_threshold": score_threshold}
    return create_detector(backend, options)


def create_replay_tracker(source: ReplaySource, stride: int) -> FrameTracker:
    """ByteTrack at the rate the replay feeds it frames (the source's rate over the stride)."""
    from merlin2_sailor.perception.tracker import ByteTrackAdapter, ByteTrackConfig

    return ByteTrackAdapter(ByteTrackConfig(frame_rate=source.frame_rate / stride))
