"""The ``mission_demo`` node: the README's main job, a mission in the simulated house, with a report.

It drives the graph of ``launch/demo.yaml`` (world, perception, anchoring, knowledge base,
behaviours) through two missions and scores the result against the world's ground truth:

1. look around the room the robot starts in, explore the rest of the house (``explored`` every
   waypoint), then go to the hall: everything in view gets anchored, and the knowledge base says
   where;
2. the red mug is named by its anchor (the user points at it: the demo looks up which anchor is
   where the world has the red mug), and the world moves the mug while the robot is away;
3. "find the red mug and go to it" (``robot_near(<symbol>)``): the plan relies on where the mug
   was; on arrival the camera sees the place empty, the fact is retracted, the mission replans,
   find_object searches and reacquires the mug elsewhere under the same symbol.

While it runs it prints the running account and saves an annotated camera frame every
``frame_period`` seconds; at the end it writes the report folder (summary.md, scorecard.json,
map.png, frames/, knowledge.pddl, account.log) and exits 0 when the demo showed what it should.
"""

from __future__ import annotations

import json
import math
import threading
import time
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from geometry_msgs.msg import PoseStamped
from rclpy.node import Node
from sensor_msgs.msg import CameraInfo, Image

from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import ConfigurationError, SailorError
from merlin2_sailor.knowledge import ChangeEvent, Proposition
from merlin2_sailor.knowledge.grounding import Grounding, GroundingConfig
from merlin2_sailor.knowledge.pddl_writer import domain_from_store, problem_from_store
from merlin2_sailor.resources import config_path
from merlin2_sailor.ros.conversions.perception import camera_info_to_intrinsics, pose_from_message
from merlin2_sailor.ros.conversions.sensors import depth_to_metres, image_to_array
from merlin2_sailor.ros.node_runner import run_node
from merlin2_sailor.ros.parameters import declare_parameter
from merlin2_sailor.ros.qos import EVENTS, LATCHED, SENSOR_DATA
from merlin2_sailor_behaviors.mission.account import AnchorEventWording, describe_fact_changes
from merlin2_sailor_behaviors.mission.mission_node import anchor_event_lines, open_knowledge_base
from merlin2_sailor_behaviors.mission.session import ForwardToRosLogger, MissionSession, SessionConfig
from merlin2_sailor_demos.report import (
    AnchorRecord,
    DemoOutcome,
    IdentityHistory,
    MapLayers,
    TrueObject,
    associate,
    truth_from_ground_truth,
    write_report,
)
from merlin2_sailor_demos.report.annotated_frame import AnchorInView, annotate_frame
from merlin2_sailor_demos.world import load_world
from merlin2_sailor_interfaces.msg import AnchorArray, AnchorEventArray

_STATE_NAMES = {0: "tentative", 1: "confirmed", 2: "missing", 3: "forgotten"}
EXPLORE_ACTIONS = ("navigation", "explore")
FETCH_ACTIONS = ("navigation", "approach_object", "find_object")


@dataclass(frozen=True)
class _FrameToDraw:
    """A colour frame due for the report, with what to draw on it, waiting for its depth image."""

    stamp: float
    colour: Image
    pose: Pose
    anchors: list[AnchorInView]
    caption: str


def _stamp(message: Any) -> float:
    return message.header.stamp.sec + message.header.stamp.nanosec * 1e-9


_SAME_FRAME = 0.005  # s: colour and depth of one camera frame carry the same stamp


def _depth_in_metres(message: Image) -> np.ndarray | None:
    try:
        return depth_to_metres(image_to_array(message), message.encoding)
    except SailorError:
        return None


class MissionDemoNode(Node):
    """Runs the demo on a worker thread; sets ``exit_code`` when the report is written."""

    def __init__(self, **options: Any) -> None:
        super().__init__("mission_demo", **options)
        self._folder = Path(declare_parameter(
            self, "report_folder", "~/.sailor/house/report", "Folder of the report (created when the demo runs).")
        ).expanduser()
        self._data = Path(declare_parameter(
            self, "data_folder", "", "Where the world writes ground_truth.json (default: the report folder's parent)."
        ) or self._folder.parent).expanduser()
        world_file = config_path(declare_parameter(
            self, "world_file", "worlds/house.yaml", "The world the demo runs in (for the map)."), "worlds/house.yaml")
        grounding_file = config_path(declare_parameter(
            self, "grounding", "worlds/house_grounding.yaml", "The grounding the anchoring node uses."),
            "grounding.yaml")
        self._target = declare_parameter(self, "target", "red_mug", "World id of the object to find.")
        self._away_from = declare_parameter(
            self, "wait_at", "hall", "Waypoint the robot goes to after exploring, while the world moves the target.")
        self._frame_period = declare_parameter(
            self, "frame_period", 2.0, "Seconds between annotated frames saved.", minimum=0.2, maximum=600.0)
        self._move_timeout = declare_parameter(
            self, "move_timeout", 30.0, "Seconds to wait for the world to move the target.", minimum=1.0,
            maximum=600.0)
        self.exit_code: int | None = None
        self._world = load_world(world_file)
        self._grounding = Grounding(GroundingConfig.from_yaml(grounding_file))
        self._store = open_knowledge_base("ros:///merlin2")
        self._session = MissionSession(
            self._store, self, SessionConfig(actions=EXPLORE_ACTIONS + FETCH_ACTIONS[1:], actions_timeout=120.0),
            self._say)
        self._account: list[str] = []
        self._lock = threading.Lock()
        self._anchors: list[AnchorRecord] = []
        self._anchor_views: list[tuple[AnchorRecord, float, tuple[float, float, float]]] = []
        self._history = IdentityHistory()
        self._path: list[tuple[float, float]] = []
        self._poses: deque[tuple[float, Any]] = deque(maxlen=60)
        self._detections: deque[tuple[float, list]] = deque(maxlen=60)
        self._depths: deque[tuple[float, Image]] = deque(maxlen=5)  # converted only when a frame is drawn
        self._pending_frame: _FrameToDraw | None = None
        self._intrinsics = None
        self._last_frame_time = 0.0
        self._frames = 0
        self._words = AnchorEventWording()
        self._initial_truth: list[TrueObject] = []
        self._unsubscribe = self._store.subscribe(self._on_fact_changes)
        self.create_subscription(AnchorArray, "/anchors", self._on_anchors, LATCHED)
        self.create_subscription(AnchorEventArray, "/anchor_events", self._on_anchor_events, EVENTS)
        self.create_subscription(PoseStamped, "/robot_pose", self._on_robot_pose, SENSOR_DATA)
        self.create_subscription(PoseStamped, "/camera/camera_pose", self._on_camera_pose, SENSOR_DATA)
        self.create_subscription(CameraInfo, "/camera/color/camera_info", self._on_camera_info, SENSOR_DATA)
        self.create_subscription(Image, "/camera/color/image_raw", self._on_image, SENSOR_DATA)
        self.create_subscription(Image, "/camera/depth/image_raw", self._on_depth, SENSOR_DATA)
        self.create_timer(1.0, self._record_identities)
        self._log_handler = ForwardToRosLogger(self, say=self._say)
        self._log_handler.attach()
        self._started = time.monotonic()
        self._worker = threading.Thread(target=self._run, name="mission-demo", daemon=True)
        self._worker.start()

    # The story.

    def _run(self) -> None:
        try:
            self.exit_code = 0 if self._demo() else 1
        except SailorError as error:
            self._say(f"the demo cannot go on: {error}")
            self.exit_code = 2

    def _demo(self) -> bool:
        self._say(f"waiting for the graph; the report goes to {self._folder}")
        self._session.wait_until_ready()
        self._initial_truth = self._truth()
        waypoints = [waypoint.name for waypoint in self._grounding.config.waypoints]
        missions: list[tuple[str, bool, str]] = []
        # Aries is satisficing: asked for every room at once, it may explore the room the robot
        # stands in last, after a drive back to it. Looking around here first is one plain step.
        here = self._robot_place()
        if here in waypoints:
            look = self._session.run([Proposition("explored", (here,), is_goal=True)], f"look around the {here}",
                                     EXPLORE_ACTIONS)
            missions.append((f"look around the {here}", look.succeeded, look.reason))
        rest = [w for w in waypoints if w != here]
        explore = self._session.run(
            [Proposition("explored", (w,), is_goal=True) for w in rest], "explore the house", EXPLORE_ACTIONS)
        missions.append(("explore the house", explore.succeeded, explore.reason))
        if all(ok for _, ok, _ in missions) and self._away_from in waypoints:  # leave, so the world may move the mug
            away = self._session.run(
                [Proposition("robot_at", (self._away_from,), is_goal=True)], f"go to the {self._away_from}",
                EXPLORE_ACTIONS)
            missions.append((f"go to the {self._away_from}", away.succeeded, away.reason))
        symbol = self._identify_target()
        if not all(ok for _, ok, _ in missions) or symbol is None:
            return self._finish(missions, symbol or "", found=False)
        start = next((obj.position for obj in self._initial_truth if obj.id == self._target), None)
        self._say(f"waiting for the world to move the {self._target.replace('_', ' ')} while the robot is away")
        deadline = time.monotonic() + self._move_timeout
        while time.monotonic() < deadline and self._target_position() == start:
            time.sleep(0.5)
        moved = self._target_position() != start
        self._say(f"the {self._target.replace('_', ' ')} was moved" if moved else "the world did not move it")
        name = f"find the {self._target.replace('_', ' ')} ({symbol}) and go to it"
        fetch = self._session.run([Proposition("robot_near", (symbol,), is_goal=True)], name, FETCH_ACTIONS)
        missions.append((name, fetch.succeeded, f"{fetch.reason}; {fetch.replans} replan(s)"))
        return self._finish(missions, symbol, found=fetch.succeeded and moved)

    def _robot_place(self) -> str | None:
        """The waypoint the knowledge base has the robot at (the behaviors node declares it)."""
        facts = self._store.propositions.get_all()
        places = [fact.objects[0] for fact in facts if fact.predicate == "robot_at" and not fact.is_goal]
        return places[0] if places else None

    def _identify_target(self) -> str | None:
        """The symbol of the anchor where the target was put at the start: the user pointing at it
        (the world may already have moved it: it does so as soon as the robot is away)."""
        truth = [obj for obj in self._initial_truth if obj.id == self._target]
        with self._lock:
            anchors = [a for a in self._anchors if a.state == "confirmed"]
        symbol = associate(truth, anchors).get(self._target) if truth else None
        self._say(f"the {self._target.replace('_', ' ')} is anchored as {symbol}" if symbol
                  else f"the {self._target.replace('_', ' ')} was not anchored while exploring")
        return symbol

    def _finish(self, missions: list[tuple[str, bool, str]], symbol: str, found: bool) -> bool:
        time.sleep(1.5)  # let the last anchors and facts arrive
        truth = self._truth()
        with self._lock:
            anchors = list(self._anchors)
        target = next((obj for obj in truth if obj.id == self._target), None)
        kept = next((a for a in anchors if a.symbol == symbol), None)
        error = math.dist(target.position, kept.position) if target and kept else float("inf")
        outcome = DemoOutcome(missions, self._target, symbol, found and error <= 0.3, error,
                              time.monotonic() - self._started)
        facts = [p.objects for p in self._store.propositions.get_all() if p.predicate == "object_at" and not p.is_goal]
        card = write_report(
            self._folder, truth, anchors, [tuple(f) for f in facts], self._place_of, self._layers(), self._history,
            f"{domain_from_store(self._store)}\n\n{problem_from_store(self._store)}", self._account, outcome)
        self._say(f"report written to {self._folder}: summary.md, scorecard.json, map.png, "
                  f"{self._frames} frames, knowledge.pddl")
        for line in card.to_markdown().splitlines():
            self._say(line)
        self._say(f"demo {'succeeded' if outcome.succeeded else 'failed'} in {outcome.seconds:.0f} s")
        return outcome.succeeded

    # Helpers.

    def _truth(self) -> list[TrueObject]:
        try:
            return truth_from_ground_truth(json.loads((self._data / "ground_truth.json").read_text()))
        except (OSError, ValueError) as error:
            raise ConfigurationError(f"no ground truth from the world in {self._data}: {error}") from error

    def _target_position(self) -> tuple[float, ...] | None:
        try:
            return next((o.position for o in self._truth() if o.id == self._target), None)
        except ConfigurationError:
            return None

    def _place_of(self, obj: TrueObject) -> str | None:
        record = AnchorRecord("truth_probe", obj.class_name, obj.position)
        grounded = self._grounding.ground([_Groundable(record)])
        facts = grounded["truth_probe"].facts
        return next((f.objects[1] for f in facts if f.predicate == self._grounding.config.at_predicate), None)

    def _layers(self) -> MapLayers:
        house = self._world.house
        return MapLayers(
            rooms=[(r.name, (r.x_min, r.y_min, r.x_max, r.y_max)) for r in house.rooms],
            furniture=[(float(f.box.minimum[0]), float(f.box.minimum[1]), float(f.box.maximum[0]),
                        float(f.box.maximum[1])) for f in house.furniture],
            waypoints=[(w.name, w.pose.x, w.pose.y) for w in house.waypoints],
            robot_path=list(self._path))

    def _say(self, line: str) -> None:
        self._account.append(line)
        self.get_logger().info(line)

    # Callbacks.

    def _on_fact_changes(self, events: Sequence[ChangeEvent]) -> None:
        for line in describe_fact_changes(events):
            self._say(f"fact {line}")

    def _on_anchor_events(self, message: AnchorEventArray) -> None:
        for line in anchor_event_lines(self._words, message):
            self._say(line)

    def _on_anchors(self, message: AnchorArray) -> None:
        records = [
            AnchorRecord(a.symbol, a.class_name, (a.position.x, a.position.y, a.position.z),
                         _STATE_NAMES.get(a.state, "?"))
            for a in message.anchors
        ]
        views = [(record, a.last_seen.sec + a.last_seen.nanosec * 1e-9, (a.size.x, a.size.y, a.size.z))
                 for record, a in zip(records, message.anchors, strict=True)]
        with self._lock:
            self._anchors = records
            self._anchor_views = views

    def _record_identities(self) -> None:
        try:
            truth = self._truth()
        except ConfigurationError:
            return
        with self._lock:
            anchors = [a for a in self._anchors if a.state in ("confirmed", "missing")]
        self._history.record(associate(truth, anchors))

    def _on_robot_pose(self, message: PoseStamped) -> None:
        point = (message.pose.position.x, message.pose.position.y)
        if not self._path or math.dist(point, self._path[-1]) > 0.1:
            self._path.append(point)

    def _on_camera_pose(self, message: PoseStamped) -> None:
        self._poses.append((_stamp(message), pose_from_message(message.pose)))

    def _on_camera_info(self, message: CameraInfo) -> None:
        if self._intrinsics is None:
            self._intrinsics = camera_info_to_intrinsics(message)

    def _on_depth(self, message: Image) -> None:
        stamp = _stamp(message)
        self._depths.append((stamp, message))
        if self._pending_frame is not None and abs(self._pending_frame.stamp - stamp) < _SAME_FRAME:
            self._draw(self._pending_frame, _depth_in_metres(message))

    def _depth_at(self, stamp: float) -> np.ndarray | None:
        """The depth image of the colour frame at ``stamp`` in metres; None if not here or bad."""
        message = next((m for t, m in reversed(self._depths) if abs(t - stamp) < _SAME_FRAME), None)
        return _depth_in_metres(message) if message is not None else None

    def _on_image(self, message: Image) -> None:
        now = time.monotonic()
        if now - self._last_frame_time < self._frame_period or self._intrinsics is None:
            return
        stamp = _stamp(message)
        pose = next((p for t, p in reversed(self._poses) if abs(t - stamp) < 0.05), None)
        if pose is None:
            return
        self._last_frame_time = now
        with self._lock:
            views = [AnchorInView(r.symbol, r.state, r.position, size, abs(seen - stamp) < 0.3)
                     for r, seen, size in self._anchor_views if r.state != "tentative"]
        caption = f"t={now - self._started:5.1f} s  {self._account[-1][:80] if self._account else ''}"
        if self._pending_frame is not None:  # its depth never came: drawn without the occlusion test
            self._draw(self._pending_frame, None)
        frame = _FrameToDraw(stamp, message, pose, views, caption)
        depth = self._depth_at(stamp)
        if depth is not None:
            self._draw(frame, depth)
        else:  # the depth of the same frame usually arrives just after the colour
            self._pending_frame = frame

    def _draw(self, frame: _FrameToDraw, depth: np.ndarray | None) -> None:
        """Save the annotated frame; with depth, anchors behind walls are left out."""
        self._pending_frame = None
        try:
            rgb = image_to_array(frame.colour)
        except SailorError:
            return
        drawn = annotate_frame(rgb, self._intrinsics, frame.pose, frame.anchors, caption=frame.caption, depth=depth)
        self._frames += 1
        path = self._folder / "frames" / f"frame_{self._frames:04d}.png"
        path.parent.mkdir(parents=True, exist_ok=True)
        cv2.imwrite(str(path), cv2.cvtColor(drawn, cv2.COLOR_RGB2BGR))

    def destroy_node(self) -> None:
        self._session.cancel()
        self._worker.join(timeout=10.0)
        self._session.close()
        self._log_handler.detach()
        self._unsubscribe()
        self._store.close()
        super().destroy_node()


class _Groundable:
    """An AnchorRecord as the grounding reads anchors (to ask where a true object would be put)."""

    def __init__(self, record: AnchorRecord) -> None:
        self.symbol = record.symbol
        self.class_name = record.class_name
        self.position = record.position
        self.size = (0.1, 0.1, 0.1)
        self.state = "confirmed"
        self.visible = True


def main(argv: Sequence[str] | None = None) -> int:
    return run_node(MissionDemoNode, argv)
