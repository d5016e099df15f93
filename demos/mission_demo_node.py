"""The ``mission_demo`` node: the README's main job, a mission in the simulated house, with a report.

It drives the graph of ``launch/demo.yaml`` (world, perception, anchoring, knowledge base,
behaviours) through the missions of the world file's ``mission`` section
(:mod:`merlin2_sailor_demos.world.mission`; without one, the default story below) and scores
the result against the world's ground truth:

1. look around the room the robot starts in, explore the rest of the house (``explored`` every
   waypoint, or those the mission names): everything in view gets anchored, and the knowledge
   base says where;
2. the target (the red mug) is named by its anchor (the user points at it: the demo looks up
   which anchor is where the world had the mug at the start), and so is every other object;
3. the route: go to the hall, and wait while the world moves the mug behind the robot's back
   (a scenario may have several stops, each waiting for events of its own);
4. "find the red mug and go to it" (``robot_near(<symbol>)``): the plan relies on where the mug
   was; on arrival the camera sees the place empty, the fact is retracted, the mission replans,
   find_object searches and reacquires the mug elsewhere under the same symbol.

While it runs it prints the running account and saves an annotated camera frame every
``frame_period`` seconds; at the end it writes the report folder (summary.md, scorecard.json,
map.png, frames/, knowledge.pddl, account.log). scorecard.json's ``claims`` say what the
mission claimed and what each symbol refers to (by its anchor's last sighting), and
``verdict`` whether the claims are true (:mod:`merlin2_sailor_demos.report.verdict`). It exits
0 when the demo showed what it should: the default story succeeded or, for a world file with a
mission, the verdict is right.
"""

from __future__ import annotations

import json
import math
import threading
import time
import traceback
from collections import deque
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from dataclasses import replace as dataclass_replace
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
from merlin2_sailor_behaviors.planning import MissionResult
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
from merlin2_sailor_demos.report.merges import MergeLog
from merlin2_sailor_demos.report.naming import symbols_before_change
from merlin2_sailor_demos.report.scorecard import CLAIMING_STATES
from merlin2_sailor_demos.report.truth_timeline import TruthTimeline, refers_to
from merlin2_sailor_demos.world import load_world
from merlin2_sailor_demos.world.mission import MissionSpec, RouteStop
from merlin2_sailor_demos.world.scenario import ScenarioEvent
from merlin2_sailor_interfaces.msg import AnchorArray, AnchorEvent, AnchorEventArray

_STATE_NAMES = {0: "tentative", 1: "confirmed", 2: "missing", 3: "forgotten"}
EXPLORE_ACTIONS = ("navigation", "explore")
FETCH_ACTIONS = ("navigation", "approach_object", "find_object")
#: An anchor seen this recently (s) is in view: only those are associated for the identity
#: history, as MOT metrics associate only the hypotheses of the current frame (a stale anchor
#: where another object now stands is no confusion the robot made).
FRESH_SECONDS = 1.5
#: Seconds to let the last anchors and facts arrive before the report (and the identification).
SETTLE_SECONDS = 1.5
_PAST = {"move": "moved", "remove": "removed", "add": "added"}


@dataclass(frozen=True)
class _FrameToDraw:
    """A colour frame due for the report, with what to draw on it, waiting for its depth image."""

    stamp: float
    colour: Image
    pose: Pose
    anchors: list[AnchorInView]
    caption: str


def _stamp(message: Any) -> float:
    """The stamp of a message with a header, or of one that is stamped itself (an anchor event)."""
    stamp = message.header.stamp if hasattr(message, "header") else message.stamp
    return stamp.sec + stamp.nanosec * 1e-9


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
        target = declare_parameter(
            self, "target", "", "World id of the object to find; empty: the world file's mission's (red_mug).")
        wait_at = declare_parameter(
            self, "wait_at", "", "Waypoint the robot goes to after exploring, while the world moves the target; "
            "empty: the world file's mission's route (the hall).")
        self._frame_period = declare_parameter(
            self, "frame_period", 2.0, "Seconds between annotated frames saved.", minimum=0.2, maximum=600.0)
        self._move_timeout = declare_parameter(
            self, "move_timeout", 30.0, "Seconds to wait for the world to move the target.", minimum=1.0,
            maximum=600.0)
        self.exit_code: int | None = None
        self._world = load_world(world_file)
        mission = self._world.mission or MissionSpec()
        self._judged = self._world.mission is not None  # a scenario: its verdict decides the exit code
        if target:
            mission = dataclass_replace(mission, target=target)
        if wait_at:
            mission = dataclass_replace(mission, route=(RouteStop(wait_at),))
        self._mission = mission
        self._target = mission.target
        self._symbols_before: dict[str, str] = {}
        self._timeline = TruthTimeline()
        self._ambiguous: list[dict[str, Any]] = []  # the anchoring layer's "cannot tell apart" events
        self._acquired_because: dict[str, str] = {}  # symbol -> its acquired event's nearest_anchor
        self._merges = MergeLog()  # every anchor forgotten into another, judged against the truth
        self._awaited: set[str] = set()  # the world's events a route stop has waited for
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
        except Exception as error:  # a bug, or a planner engine that broke: end the demo, never hang it
            self._say(f"the demo failed: {type(error).__name__}: {error}")
            self.get_logger().error(traceback.format_exc())
            self.exit_code = 1

    def _demo(self) -> bool:
        self._say(f"waiting for the graph; the report goes to {self._folder}")
        self._session.wait_until_ready()
        self._initial_truth = self._truth()
        waypoints = [waypoint.name for waypoint in self._grounding.config.waypoints]
        wanted = list(self._mission.explore) if self._mission.explore is not None else waypoints
        missions: list[tuple[str, bool, str]] = []
        # Aries is satisficing: asked for every room at once, it may explore the room the robot
        # stands in last, after a drive back to it. Looking around here first is one plain step.
        here = self._robot_place()
        if here in wanted:
            look = self._session.run([Proposition("explored", (here,), is_goal=True)], f"look around the {here}",
                                     EXPLORE_ACTIONS)
            missions.append((f"look around the {here}", look.succeeded, look.reason))
        rest = [w for w in wanted if w != here]
        if rest and all(ok for _, ok, _ in missions):
            explore = self._session.run(
                [Proposition("explored", (w,), is_goal=True) for w in rest], "explore the house", EXPLORE_ACTIONS)
            missions.append(("explore the house", explore.succeeded, explore.reason))
        explored = all(ok for _, ok, _ in missions)
        symbol = self._identify_target() if explored else None
        if symbol is None:
            why = "the target was not anchored while exploring" if explored else "exploring failed"
            return self._finish(missions, "", found=False, fetch=None, why=why)
        changed = True
        for stop in self._mission.route:
            if stop.go_to is not None:  # even where the robot already is: the goal holds at once
                away = self._session.run(
                    [Proposition("robot_at", (stop.go_to,), is_goal=True)], f"go to the {stop.go_to}",
                    EXPLORE_ACTIONS)
                missions.append((f"go to the {stop.go_to}", away.succeeded, away.reason))
                if not away.succeeded:
                    return self._finish(missions, symbol, found=False, fetch=None, why=f"going to {stop.go_to} failed")
            changed = self._wait_for_events(stop.wait_for) and changed
        name = f"find the {self._target.replace('_', ' ')} ({symbol}) and go to it"
        fetch = self._session.run([Proposition("robot_near", (symbol,), is_goal=True)], name, FETCH_ACTIONS)
        missions.append((name, fetch.succeeded, f"{fetch.reason}; {fetch.replans} replan(s)"))
        return self._finish(missions, symbol, found=fetch.succeeded and changed, fetch=fetch)

    def _wait_for_events(self, names: tuple[str, ...] | None) -> bool:
        """Wait (up to ``move_timeout``) for the world to fire ``names`` (None: every event no
        earlier stop waited for); say what happened. True when all of them fired."""
        events = {event.name: event for event in self._world.scenario}
        awaited = [name for name in events if name not in self._awaited] if names is None else list(names)
        self._awaited.update(awaited)
        if not awaited:
            return True
        unseen = not any(events[name].watched for name in awaited if name in events)
        self._say(f"waiting for the world to {_and(_phrase(events.get(name), name) for name in awaited)}"
                  + (" while the robot is away" if unseen else ""))
        deadline = time.monotonic() + self._move_timeout
        while time.monotonic() < deadline and not set(awaited) <= self._fired_events():
            time.sleep(0.5)
        fired = self._fired_events()
        for name in awaited:
            event = events.get(name)
            if name in fired:
                self._say(_happened(event, name))
            else:
                self._say("the world did not " + ("move it" if event is not None and event.action == "move"
                                                  else _phrase(event, name)))
        return set(awaited) <= fired

    def _fired_events(self) -> set[str]:
        """The names of the events the world has fired (from its ground_truth.json)."""
        try:
            data = json.loads((self._data / "ground_truth.json").read_text())
        except (OSError, ValueError):
            return set()
        return {event["name"] for event in data.get("events", [])}

    def _robot_place(self) -> str | None:
        """The waypoint the knowledge base has the robot at (the behaviors node declares it)."""
        facts = self._store.propositions.get_all()
        places = [fact.objects[0] for fact in facts if fact.predicate == "robot_at" and not fact.is_goal]
        return places[0] if places else None

    def _identify_target(self) -> str | None:
        """The symbol of the anchor where the target was put at the start: the user pointing at it
        (the rules: :func:`symbols_before_change`). Every other object is named the same way, so
        the report can tell whose symbol went where."""
        time.sleep(SETTLE_SECONDS)  # the last look's anchors are confirmed a moment after it ends
        with self._lock:
            anchors = list(self._anchors)
        target_now = next((obj for obj in self._truth() if obj.id == self._target), None)
        self._symbols_before = symbols_before_change(self._initial_truth, target_now, anchors)
        symbol = self._symbols_before.get(self._target)
        self._say(f"the {self._target.replace('_', ' ')} is anchored as {symbol}" if symbol
                  else f"the {self._target.replace('_', ' ')} was not anchored while exploring")
        return symbol

    def _finish(self, missions: list[tuple[str, bool, str]], symbol: str, found: bool,
                fetch: MissionResult | None, why: str = "") -> bool:
        time.sleep(SETTLE_SECONDS)  # let the last anchors and facts arrive
        truth = self._truth()
        with self._lock:
            anchors = list(self._anchors)
            views = list(self._anchor_views)
        target = next((obj for obj in truth if obj.id == self._target), None)
        kept = next((a for a in anchors if a.symbol == symbol), None)
        error = math.dist(target.position, kept.position) if target and kept else float("inf")
        outcome = DemoOutcome(missions, self._target, symbol, found and error <= 0.3, error,
                              time.monotonic() - self._started)
        facts = [p.objects for p in self._store.propositions.get_all() if p.predicate == "object_at" and not p.is_goal]
        claims = self._claims(symbol, target, views, facts, fetch, why)
        card, verdict = write_report(
            self._folder, truth, anchors, [tuple(f) for f in facts], self._place_of, self._layers(), self._history,
            f"{domain_from_store(self._store)}\n\n{problem_from_store(self._store)}", self._account, outcome,
            claims, acquired_because=self._acquired_because_now())
        self._say(f"report written to {self._folder}: summary.md, scorecard.json, map.png, "
                  f"{self._frames} frames, knowledge.pddl")
        for line in card.to_markdown().splitlines():
            self._say(line)
        self._say(f"demo {'succeeded' if outcome.succeeded else 'failed'} in {outcome.seconds:.0f} s")
        self._say(f"claims against the ground truth: {verdict.outcome}, {'right' if verdict.right else 'WRONG'}"
                  + (f" ({'; '.join(verdict.problems)})" if verdict.problems else ""))
        return verdict.right if self._judged else outcome.succeeded

    def _acquired_because_now(self) -> dict[str, str]:
        with self._lock:
            return dict(self._acquired_because)

    def _claims(self, symbol: str, target: TrueObject | None, views: list, facts: list, fetch: MissionResult | None,
                why: str) -> dict[str, Any]:
        """The ``claims`` section of scorecard.json (what :func:`verdict.judge` reads)."""
        claiming = [(record, seen) for record, seen, _ in views if record.state in CLAIMING_STATES]
        places: dict[str, list[str]] = {}
        for fact in facts:
            places.setdefault(fact[0], []).append(fact[1])
        with self._lock:
            refers = {record.symbol: refers_to(record, seen, self._timeline) for record, seen in claiming}
            ambiguous = list(self._ambiguous)
            merges = [asdict(merge) for merge in self._merges.judged(self._timeline)]
        return {
            "world": self._world.source,
            "target": self._target,
            "target_symbol": symbol,
            "target_present": target is not None,
            "target_place": self._place_of(target) if target is not None else None,
            "symbols_before": dict(self._symbols_before),
            "refers_to": refers,
            "last_seen": {record.symbol: round(seen, 3) for record, seen in claiming},
            "object_at": places,
            "fetch": {"ran": fetch is not None, "succeeded": bool(fetch and fetch.succeeded),
                      "reason": fetch.reason if fetch is not None else why},
            "ambiguous": ambiguous,
            "merges": merges,
            "expect": self._mission.expect.as_dict(),
        }

    # Helpers.

    def _truth(self) -> list[TrueObject]:
        """The world's ground truth now; each version read is kept on the timeline."""
        try:
            data = json.loads((self._data / "ground_truth.json").read_text())
        except (OSError, ValueError) as error:
            raise ConfigurationError(f"no ground truth from the world in {self._data}: {error}") from error
        truth = truth_from_ground_truth(data)
        with self._lock:
            self._timeline.record(float(data.get("stamp", time.time())), truth)
        return truth

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
        for event in message.events:
            if event.kind == AnchorEvent.KIND_ACQUIRED:
                # Why it was not taken for an anchor already there: a duplicate's first question.
                nearest = next((item.value for item in event.details if item.key == "nearest_anchor"), "")
                with self._lock:
                    self._acquired_because[event.symbol] = nearest
            if event.kind == AnchorEvent.KIND_FORGOTTEN:
                details = {item.key: item.value for item in event.details}
                if details.get("into"):
                    with self._lock:
                        self._merges.note_forgotten(event.symbol, details["into"], _stamp(event),
                                                    details.get("reason", ""))
            if event.kind == AnchorEvent.KIND_AMBIGUOUS:
                with self._lock:
                    self._ambiguous.append({"symbol": event.symbol, "stamp": _stamp(event),
                                            "details": {item.key: item.value for item in event.details}})

    def _on_anchors(self, message: AnchorArray) -> None:
        records = [
            AnchorRecord(a.symbol, a.class_name, (a.position.x, a.position.y, a.position.z),
                         _STATE_NAMES.get(a.state, "?"), tuple(a.indistinguishable_from))
            for a in message.anchors
        ]
        views = [(record, a.last_seen.sec + a.last_seen.nanosec * 1e-9, (a.size.x, a.size.y, a.size.z))
                 for record, a in zip(records, message.anchors, strict=True)]
        with self._lock:
            self._anchors = records
            self._anchor_views = views
            for record, seen, size in views:
                self._merges.note_view(record, seen, size)

    def _record_identities(self) -> None:
        try:
            truth = self._truth()
        except ConfigurationError:
            return
        now = time.time()  # the anchors' stamps are the camera's: the system clock
        with self._lock:
            anchors = [record for record, seen, _ in self._anchor_views
                       if record.state in CLAIMING_STATES and now - seen <= FRESH_SECONDS]
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


def _phrase(event: ScenarioEvent | None, name: str) -> str:
    """What an event does, as the running account says it ("move the red mug")."""
    if event is None:
        return f"fire {name}"
    return f"{event.action} the {event.object_id.replace('_', ' ')}"


def _happened(event: ScenarioEvent | None, name: str) -> str:
    if event is None:
        return f"{name} happened"
    return f"the {event.object_id.replace('_', ' ')} was {_PAST.get(event.action, event.action)}"


def _and(phrases: Any) -> str:
    phrases = list(phrases)
    return phrases[0] if len(phrases) == 1 else ", ".join(phrases[:-1]) + " and " + phrases[-1]


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
