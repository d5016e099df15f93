"""The simulated world: the house, its objects and the robot, advanced in time and sensed.

:class:`World` ties the parts together and is all a node (or a test, or a benchmark) needs:
``step(dt)`` drives the robot and fires the scenario, ``navigate_to`` starts a goal, ``render``
returns an RGB-D frame from the true camera pose, ``detect`` returns ground-truth detections, ``pick``
and ``place`` work the gripper, and ``ground_truth`` exports everything as plain data.

The robot's controller sees the odometry estimate; the camera renders from the true pose; the
published camera pose is the estimate. So what the anchoring layer gets is as consistent, and as
wrong, as on a real robot. Not thread-safe: the node serialises calls with a lock.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum
from typing import Any

import numpy as np

from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import InvalidInputError
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor_demos.world.geometry import Box, Pose2D
from merlin2_sailor_demos.world.gripper import GraspResult, Gripper
from merlin2_sailor_demos.world.ground_truth_detector import DetectorNoise, GroundTruthDetector
from merlin2_sailor_demos.world.motion import PathFollower, integrate
from merlin2_sailor_demos.world.navigation import NavigationGraph, Plan
from merlin2_sailor_demos.world.objects import ObjectSpec, WorldObject
from merlin2_sailor_demos.world.odometry import Odometry
from merlin2_sailor_demos.world.renderer import Renderer
from merlin2_sailor_demos.world.scenario import FiredEvent, Progress, Scenario, ScenarioEvent
from merlin2_sailor_demos.world.textures import TextureLibrary
from merlin2_sailor_demos.world.visibility import Visibility, visible_geometric, visible_in_frame
from merlin2_sailor_demos.world.world_file import WorldDescription

#: Longest simulation step (s); longer ``step`` calls are split, so motion does not depend on the caller's rate.
PHYSICS_STEP = 0.02
#: A goal this close (m) to a waypoint counts as a visit to it (scenario ``after_visiting``).
VISIT_RADIUS = 0.3
#: The robot counts as moving while its true pose changes by more than this per step (m, rad).
STILL_TOLERANCE = 1e-4


@dataclass
class _Glide:
    """A ``move`` with a speed, under way: the object travels from ``source`` to the destination."""

    event: ScenarioEvent
    item: WorldObject
    source: tuple[float, float, float]


class NavigationState(Enum):
    ACTIVE = "active"
    ARRIVED = "arrived"
    CANCELED = "canceled"
    PREEMPTED = "preempted"


@dataclass
class NavigationGoal:
    id: int
    x: float
    y: float
    yaw: float | None
    plan: Plan
    follower: PathFollower
    started: float
    state: NavigationState = NavigationState.ACTIVE
    finished: float | None = None


@dataclass(frozen=True, eq=False)
class SensorFrame:
    """One camera frame: colour (RGB), measured depth (m, NaN invalid), truth, and both camera poses."""

    time: float
    color: np.ndarray
    depth: np.ndarray
    true_depth: np.ndarray
    instance: np.ndarray
    camera_pose: Pose  # estimated: what the robot believes
    true_camera_pose: Pose


class World:
    def __init__(self, description: WorldDescription, seed: int = 0, detector_noise: DetectorNoise | None = None,
                 darknet_data: str | None = None, segment: bool = False) -> None:
        self.description = description
        self.house = description.house
        self.camera = description.camera
        odometry_seed, depth_seed, detector_seed = np.random.SeedSequence(seed).spawn(3)
        self._depth_rng = np.random.default_rng(depth_seed)
        self.objects: list[WorldObject] = [self._new_object(spec) for spec in description.objects]
        self.time = 0.0
        robot = description.robot
        self.true_pose = robot.start
        self.odometry = Odometry(robot.odometry, np.random.default_rng(odometry_seed), robot.start)
        self._since_fix = 0.0  # seconds of motion since the localiser last corrected the estimate
        self.graph = NavigationGraph(self.house, robot.radius)
        self.gripper = Gripper(robot.gripper)
        self.scenario = Scenario(description.scenario)
        self.textures = TextureLibrary(description.textures, darknet_data)
        self.renderer = Renderer(self.house, self.camera, self.textures)
        classes = sorted({spec.class_name for spec in description.objects})
        self.detector = GroundTruthDetector(detector_noise or DetectorNoise(), self.camera.width, self.camera.height,
                                            classes, np.random.default_rng(detector_seed), segment)
        self.arrivals = 0
        self.visited: set[str] = set()
        self.version = 0
        """Incremented whenever the ground truth changes beyond the robot's motion (objects, arrivals)."""
        self._goals = 0
        self.navigation: NavigationGoal | None = None
        self._last_motion = 0.0  # simulated time the robot last moved or turned
        self._visited_since: dict[str, set[str]] = {}  # fired event -> waypoints arrived at since
        self._glides: list[_Glide] = []

    # --- time -------------------------------------------------------------------------------------------

    def step(self, dt: float) -> list[FiredEvent]:
        """Advance ``dt`` seconds: motion, odometry, arrival; then the scenario. Returns the events fired."""
        if not (dt >= 0.0 and math.isfinite(dt)):
            raise InvalidInputError(f"a world step must be a finite, non-negative duration, got {dt}")
        remaining = dt
        arrived: list[FiredEvent] = []
        while remaining > 1e-12:
            step = min(PHYSICS_STEP, remaining)
            self._physics_step(step)
            arrived += self._advance_glides(step)
            remaining -= step
        return arrived + self._run_scenario()

    def _physics_step(self, dt: float) -> None:
        self.time += dt
        goal = self.navigation
        if goal is None or goal.follower.done:
            if goal is not None and goal.state is NavigationState.ACTIVE:
                self._arrive(goal)  # a goal where the robot already stands
            self.odometry.stop()
            return
        velocity = goal.follower.command(self.odometry.estimate, dt)
        before = self.true_pose
        self.true_pose = integrate(before, velocity, dt)
        if max(abs(self.true_pose.x - before.x), abs(self.true_pose.y - before.y),
               abs(self.true_pose.yaw - before.yaw)) > STILL_TOLERANCE:
            self._last_motion = self.time
        self.odometry.update(before, self.true_pose, dt)
        period = self.odometry.noise.localisation_period
        self._since_fix += dt
        if period > 0.0 and self._since_fix >= period:  # the localiser's periodic fix against the map
            self.odometry.correct(self.true_pose)
            self._since_fix = 0.0
        self.gripper.follow(self.true_pose)
        if goal.follower.done and goal.state is NavigationState.ACTIVE:
            self._arrive(goal)

    def _arrive(self, goal: NavigationGoal) -> None:
        goal.state, goal.finished = NavigationState.ARRIVED, self.time
        self.odometry.correct(self.true_pose)
        self.odometry.stop()
        self.arrivals += 1
        for waypoint in self.house.waypoints:
            if math.hypot(waypoint.pose.x - goal.x, waypoint.pose.y - goal.y) <= VISIT_RADIUS:
                self.visited.add(waypoint.name)
                for since in self._visited_since.values():
                    since.add(waypoint.name)
        self.version += 1

    # --- navigation ---------------------------------------------------------------------------------------

    def navigate_to(self, x: float, y: float, yaw: float | None = None) -> NavigationGoal:
        """Start driving to (x, y), facing ``yaw`` at the end (None: any heading); preempts a running goal."""
        if not all(math.isfinite(value) for value in (x, y)) or (yaw is not None and not math.isfinite(yaw)):
            raise InvalidInputError(f"navigation goal ({x}, {y}, yaw {yaw}) is not finite")
        if self.house.room_at(x, y) is None:
            raise InvalidInputError(f"navigation goal ({x:.2f}, {y:.2f}) is outside the house (bounds "
                                    f"{tuple(round(v, 2) for v in self.house.bounds)})")
        estimate = self.odometry.estimate
        plan = self.graph.plan((estimate.x, estimate.y), (x, y))
        velocity = None
        if self.navigation is not None and self.navigation.state is NavigationState.ACTIVE:
            self.navigation.state, self.navigation.finished = NavigationState.PREEMPTED, self.time
            velocity = self.navigation.follower.velocity
        self._goals += 1
        follower = PathFollower(self.description.robot.limits, plan.points, yaw, velocity)
        self.navigation = NavigationGoal(self._goals, x, y, yaw, plan, follower, self.time)
        return self.navigation

    def cancel_navigation(self, goal_id: int) -> bool:
        """Brake to a stop if ``goal_id`` is the running goal; False when it is not."""
        goal = self.navigation
        if goal is None or goal.id != goal_id or goal.state is not NavigationState.ACTIVE:
            return False
        goal.state, goal.finished = NavigationState.CANCELED, self.time
        goal.follower.stop()
        return True

    def distance_remaining(self) -> float:
        goal = self.navigation
        if goal is None or goal.state is not NavigationState.ACTIVE:
            return 0.0
        return goal.follower.remaining_distance(self.odometry.estimate)

    @property
    def estimated_pose(self) -> Pose2D:
        return self.odometry.estimate

    # --- sensing -------------------------------------------------------------------------------------------

    def camera_pose(self, estimated: bool = True) -> Pose:
        """``world <- optical frame`` of the camera, from the estimated (default) or the true robot pose."""
        return self.camera.optical_pose(self.odometry.estimate if estimated else self.true_pose)

    def render(self) -> SensorFrame:
        rendered = self.renderer.render(self.true_pose, self.objects)
        depth = self.description.depth_sensor.measure(rendered.depth, self._depth_rng)
        return SensorFrame(self.time, rendered.color, depth, rendered.depth, rendered.instance,
                           self.camera_pose(True), self.camera_pose(False))

    def visible_objects(self, frame: SensorFrame | None = None) -> list[Visibility]:
        """Objects in view (indices into ``objects``): pixel-exact from a frame, else from geometry."""
        intrinsics = self.camera.intrinsics
        if frame is not None:
            return visible_in_frame([item.box for item in self.objects], frame.instance, frame.true_camera_pose,
                                    intrinsics)
        boxes = [item.box for item in self.objects]
        visible = visible_geometric(boxes, self.camera_pose(False), intrinsics, self._wall_depth())
        return [seen for seen in visible if not self.objects[seen.index].carried]

    def detect(self, frame: SensorFrame | None = None) -> list[Detection]:
        """Ground-truth detections with the configured noise, for ``frame`` or, without one, from geometry."""
        instance = frame.instance if frame is not None else None
        return self.detector.detect(self.objects, self.visible_objects(frame), instance)

    def in_view(self, box: Box) -> bool:
        """Whether any part of ``box`` is in the camera's view now (walls occlude, furniture does not)."""
        return bool(visible_geometric([box], self.camera_pose(False), self.camera.intrinsics, self._wall_depth()))

    def _wall_depth(self) -> np.ndarray:
        return self.renderer.wall_depth(self.camera.eye(self.true_pose))[0]

    # --- manipulation -------------------------------------------------------------------------------------

    def pick(self, class_name: str, target: tuple[float, ...]) -> GraspResult:
        result = self.gripper.pick(self.objects, class_name, target, self.true_pose)
        if result.success:
            self.version += 1
        return result

    def place(self, target: tuple[float, ...] | None) -> GraspResult:
        result = self.gripper.place(self.house, target, self.true_pose)
        if result.success:
            self.version += 1
        return result

    # --- objects and the scenario -------------------------------------------------------------------------

    def object(self, object_id: str) -> WorldObject:
        for item in self.objects:
            if item.id == object_id:
                return item
        raise InvalidInputError(f"no object '{object_id}' in the world")

    def _new_object(self, spec: ObjectSpec) -> WorldObject:
        x, y = spec.xy
        position = np.array([x, y, self.house.support_height(x, y) + spec.size[2] / 2.0])
        return WorldObject(spec.id, spec.class_name, spec.size, spec.texture, position)

    def progress(self) -> Progress:
        room = self.house.room_at(self.true_pose.x, self.true_pose.y)
        return Progress(self.time, self.arrivals, frozenset(self.visited), room.name if room else None,
                        self.time - self._last_motion,
                        {name: frozenset(since) for name, since in self._visited_since.items()})

    def _run_scenario(self) -> list[FiredEvent]:
        fired = []
        for event in self.scenario.due(self.progress()):
            result = self._apply(event)
            if isinstance(result, FiredEvent):
                self._record(event, result)
                fired.append(result)
                self.version += 1
            elif isinstance(result, _Glide):
                self.scenario.start(event)
                self._glides.append(result)
        return fired

    def _advance_glides(self, dt: float) -> list[FiredEvent]:
        """Move every gliding object ``dt`` seconds further; the events of those that arrive."""
        arrived = []
        for glide in list(self._glides):
            item, event = glide.item, glide.event
            if item.carried or item not in self.objects:  # picked up or removed on the way: the glide ends
                self._glides.remove(glide)
                self._record(event, FiredEvent(event.name, "move interrupted", item.id, self.time, glide.source,
                                               None))
                continue
            target = np.array(event.destination, dtype=float)
            offset = target - item.position[:2]
            distance = float(np.hypot(*offset))
            step = event.speed * dt
            xy = target if distance <= step else item.position[:2] + offset * (step / distance)
            item.position = self._standing_at(item, float(xy[0]), float(xy[1]))
            self.version += 1
            if distance <= step:
                self._glides.remove(glide)
                fired = FiredEvent(event.name, "move", item.id, self.time, glide.source,
                                   tuple(float(v) for v in item.position))
                self._record(event, fired)
                arrived.append(fired)
        return arrived

    def _record(self, event: ScenarioEvent, fired: FiredEvent) -> None:
        self.scenario.record(event, fired)
        self._visited_since[event.name] = set()

    def _standing_at(self, item: WorldObject, x: float, y: float) -> np.ndarray:
        return np.array([x, y, self.house.support_height(x, y) + item.size[2] / 2.0])

    def _may_happen(self, event: ScenarioEvent, *boxes: Box) -> bool:
        """Whether the camera's view allows ``event`` now: all boxes in view if watched, else none."""
        seen = [self.in_view(box) for box in boxes]
        return all(seen) if event.watched else not any(seen)

    def _apply(self, event: ScenarioEvent) -> FiredEvent | _Glide | None:
        """Apply ``event`` (or start its glide) if the camera's view allows it; None means 'not now'."""
        if event.action == "add":
            new = self._new_object(event.spec)
            if not self._may_happen(event, new.box):
                return None
            self.objects.append(new)
            return FiredEvent(event.name, "add", event.object_id, self.time, None, tuple(new.position))
        try:
            item = self.object(event.object_id)
        except InvalidInputError:
            return FiredEvent(event.name, f"{event.action} skipped: no such object", event.object_id, self.time,
                              None, None)
        if item.carried or any(glide.item is item for glide in self._glides):
            return None  # wait until the robot puts it down, or it has arrived
        source = tuple(float(v) for v in item.position)
        if event.action == "remove":
            if not self._may_happen(event, item.box):
                return None
            self.objects.remove(item)
            return FiredEvent(event.name, "remove", item.id, self.time, source, None)
        moved = self._standing_at(item, *event.destination)
        if not self._may_happen(event, item.box, Box(tuple(moved), item.size)):
            return None
        if event.speed is not None:
            return _Glide(event, item, source)
        item.position = moved
        return FiredEvent(event.name, "move", item.id, self.time, source, tuple(float(v) for v in moved))

    # --- ground truth -----------------------------------------------------------------------------------

    def ground_truth(self) -> dict[str, Any]:
        """Plain data (JSON-ready) for reports and scorecards: objects, robot poses, events."""
        def room_of(x: float, y: float) -> str | None:
            room = self.house.room_at(x, y)
            return room.name if room else None

        goal = self.navigation
        return {
            "world": self.description.source,
            "time": round(self.time, 3),
            "version": self.version,
            "robot": {
                "true_pose": self.true_pose.as_dict(),
                "estimated_pose": self.odometry.estimate.as_dict(),
                "room": room_of(self.true_pose.x, self.true_pose.y),
                "arrivals": self.arrivals,
                "visited": sorted(self.visited),
                "navigation": None if goal is None else {
                    "goal": {"x": goal.x, "y": goal.y, "yaw": goal.yaw}, "state": goal.state.value,
                    "reachable": goal.plan.reachable,
                },
                "holding": self.gripper.held.id if self.gripper.held else None,
            },
            "objects": [{**item.as_dict(), "room": room_of(*item.position[:2])} for item in self.objects],
            "waypoints": {w.name: w.pose.as_dict() for w in self.house.waypoints},
            "events": [event.as_dict() for event in self.scenario.fired],
            "pending_events": [event.name for event in self.scenario.pending],
            "texture_substitutions": dict(self.textures.substitutions),
        }
