"""A tour of a simulated house, frame by frame, as the perceptual layer would hand it on.

The robot visits the house's waypoints in order and looks around at each (``turns`` turns of a
full circle's share, ``dwell`` seconds still after each), as the demo's explore action does;
then, when ``revisit`` is set, it goes back through the waypoints in reverse, so every object is
seen again minutes later, often from another side. Each frame is rendered, detected by the
ground-truth detector (with its noise and instance masks), tracked by ByteTrack and turned into
percepts by the percept generator: the same code the demo's nodes run, without DDS.

Each percept comes with the id of the world object it shows (from its instance mask), or None
for a false detection, so identities can be scored exactly.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.anchoring.visibility import CameraView
from merlin2_sailor.contract.percept import Percept
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.perception.box3d import Box3DConfig
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor.perception.percept_generator import PerceptGenerator, PerceptGeneratorConfig
from merlin2_sailor.perception.tracker import ByteTrackAdapter, ByteTrackConfig
from merlin2_sailor_demos.report.scorecard import TrueObject
from merlin2_sailor_demos.world.world import NavigationState, SensorFrame, World


@dataclass(frozen=True, slots=True)
class TourConfig:
    """``rate_hz``: frames per second (the world node's 15 by default; lower for training data);
    ``stops``: waypoint names in order (empty: every waypoint of the house, in file order);
    ``revisit``: then go back through them in reverse; ``turns`` / ``dwell`` (s): the look
    around at each stop; ``maximum_depth`` (m): the percept generator's range (the demo's 4.5);
    ``track``: run ByteTrack (tracker ids are evidence the anchoring layer uses); ``maximum_seconds``:
    a safety stop for a tour that cannot finish (a goal the robot cannot reach)."""

    rate_hz: float = 15.0
    stops: tuple[str, ...] = ()
    revisit: bool = True
    turns: int = 4
    dwell: float = 0.3
    maximum_depth: float = 4.5
    track: bool = True
    maximum_seconds: float = 1800.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.rate_hz) and 0.1 <= self.rate_hz <= 60.0):
            raise ConfigurationError(f"tour rate_hz must be in [0.1, 60], got {self.rate_hz}.")
        if self.turns < 0 or not (math.isfinite(self.dwell) and self.dwell >= 0.0):
            raise ConfigurationError("tour turns and dwell must not be negative.")
        if not (math.isfinite(self.maximum_seconds) and self.maximum_seconds > 0.0):
            raise ConfigurationError(f"tour maximum_seconds must be positive, got {self.maximum_seconds}.")


@dataclass(frozen=True, slots=True, eq=False)
class TourFrame:
    """One frame: its percepts, the world object each shows (None: a false detection), what the
    camera could see, the true objects at that moment, and the rendered frame itself."""

    stamp: float
    percepts: tuple[Percept, ...]
    object_ids: tuple[str | None, ...]
    camera: CameraView
    truth: tuple[TrueObject, ...]
    sensor: SensorFrame
    stop: str


def true_objects(world: World) -> tuple[TrueObject, ...]:
    """The world's objects as the scorecard takes them (carried ones are nowhere to be seen)."""
    return tuple(TrueObject(item.id, item.class_name, tuple(float(v) for v in item.position))
                 for item in world.objects if not item.carried)


def tour_stops(world: World, config: TourConfig) -> list[str]:
    names = list(config.stops) or [waypoint.name for waypoint in world.house.waypoints]
    known = {waypoint.name for waypoint in world.house.waypoints}
    unknown = sorted(set(names) - known)
    if unknown:
        raise ConfigurationError(f"tour stops {unknown} are not waypoints of the house; waypoints: {sorted(known)}")
    if config.revisit and len(names) > 1:
        names += names[-2::-1]
    return names


class Tour:
    """Iterate :meth:`frames` once; the world advances as it goes (see the module docstring)."""

    def __init__(self, world: World, config: TourConfig | None = None) -> None:
        self.world = world
        self.config = config or TourConfig()
        self.tracker = ByteTrackAdapter(ByteTrackConfig(frame_rate=self.config.rate_hz)) if self.config.track else None
        box3d = Box3DConfig(maximum_depth=self.config.maximum_depth)
        self.generator = PerceptGenerator(PerceptGeneratorConfig(box3d=box3d))
        self.stops = tour_stops(world, self.config)

    def frames(self) -> Iterator[TourFrame]:
        world, config = self.world, self.config
        period = 1.0 / config.rate_hz
        for stop in self.stops:
            pose = world.house.waypoint(stop).pose
            yield from self._drive(pose.x, pose.y, pose.yaw, stop, period)
            yield from self._still(config.dwell, stop, period)
            for turn in range(1, config.turns + 1):
                yaw = pose.yaw + 2.0 * math.pi * turn / config.turns
                yield from self._drive(pose.x, pose.y, math.atan2(math.sin(yaw), math.cos(yaw)), stop, period)
                yield from self._still(config.dwell, stop, period)

    def _drive(self, x: float, y: float, yaw: float, stop: str, period: float) -> Iterator[TourFrame]:
        world = self.world
        world.navigate_to(x, y, yaw)
        while world.navigation is not None and world.navigation.state is NavigationState.ACTIVE:
            if world.time > self.config.maximum_seconds:
                raise ConfigurationError(f"the tour did not reach {stop} within {self.config.maximum_seconds} s")
            yield self._frame(stop, period)

    def _still(self, seconds: float, stop: str, period: float) -> Iterator[TourFrame]:
        for _ in range(int(round(seconds / period))):
            yield self._frame(stop, period)

    def _frame(self, stop: str, period: float) -> TourFrame:
        world = self.world
        world.step(period)
        sensor = world.render()
        detections = world.detect(sensor)
        if self.tracker is not None:
            detections = self.tracker.update(detections, sensor.time)
        intrinsics = world.camera.intrinsics
        batch = self.generator.generate(detections, sensor.color, sensor.depth, intrinsics, sensor.camera_pose,
                                        sensor.time)
        dropped = {id(item.detection) for item in batch.dropped}
        kept = [detection for detection in detections if id(detection) not in dropped]
        object_ids = tuple(self._object_of(detection, sensor) for detection in kept)
        camera = CameraView(intrinsics, sensor.camera_pose, sensor.depth)
        return TourFrame(sensor.time, batch.percepts, object_ids, camera, true_objects(world), sensor, stop)

    def _object_of(self, detection: Detection, sensor: SensorFrame) -> str | None:
        """The object a detection shows: the one its instance mask covers (None: a false detection)."""
        if detection.mask is None:
            return None
        indices = sensor.instance[detection.mask]
        indices = indices[indices >= 0]
        if indices.size == 0:
            return None
        return self.world.objects[int(np.bincount(indices).argmax())].id


def object_ids_of(frames: Sequence[TourFrame]) -> set[str]:
    """Every object some frame of ``frames`` perceived."""
    return {object_id for frame in frames for object_id in frame.object_ids if object_id is not None}
