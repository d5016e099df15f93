"""world: the simulated house as a ROS node: an RGB-D robot to drive, look through and grasp with.

It wraps :class:`merlin2_sailor_demos.world.World` (ROS-free) and only converts and schedules:

- a simulation thread at ``rate_hz`` advances the world by the wall-clock time elapsed, renders a
  frame from the true pose, and publishes colour, depth, camera info, the ESTIMATED camera pose and
  ground-truth detections, all with one stamp, plus the estimated robot pose and odometry;
- action ``navigate_to_pose`` (Nav2's shape) drives the robot along the house's navigation graph;
  the simulation keeps publishing while a goal runs (the action and the grasp service run on the
  threads of a multi-threaded executor, and a lock serialises access to the world);
- service ``~/grasp`` picks the object of a class nearest a point, or places the held object
  (at the target, or ahead of the robot when the target is NaN);
- ``world_markers`` (latched) shows walls, furniture, true object positions and waypoints;
- with ``report_folder`` set, ``ground_truth.json`` is rewritten whenever the ground truth changes
  (objects moved, picked, placed; arrivals) and at exit.

Bad goals and requests end in a failed result and one log line, never in an exception.
"""

from __future__ import annotations

import json
import math
import os
import threading
import time
import traceback
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from builtin_interfaces.msg import Duration
from geometry_msgs.msg import Point, Pose, PoseStamped, Quaternion, Vector3
from nav_msgs.msg import Odometry
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node
from rclpy.time import Time
from sensor_msgs.msg import CameraInfo, Image
from std_msgs.msg import ColorRGBA, Header
from visualization_msgs.msg import Marker, MarkerArray

from merlin2_sailor.errors import ConfigurationError, InvalidInputError
from merlin2_sailor.resources import config_path
from merlin2_sailor.ros.conversions import (
    array_to_image,
    camera_info_message,
    detections_to_message,
    pose_to_message,
    seconds_to_stamp,
)
from merlin2_sailor.ros.navigation_interface import (
    NavigationErrorCode,
    navigate_to_pose_type,
    navigation_interface_name,
)
from merlin2_sailor.ros.node_runner import run_node
from merlin2_sailor.ros.parameters import declare_parameter
from merlin2_sailor.ros.qos import LATCHED, SENSOR_DATA
from merlin2_sailor_demos.world import DetectorNoise, NavigationState, World, load_world
from merlin2_sailor_demos.world.markers import MarkerItem, world_markers, yaw_to_quaternion
from merlin2_sailor_interfaces.msg import DetectionArray
from merlin2_sailor_interfaces.srv import Grasp

NODE_NAME = "world"
DEFAULT_WORLD_FILE = "worlds/house.yaml"
GROUND_TRUTH_FILE = "ground_truth.json"
FEEDBACK_PERIOD = 0.1  # seconds between two navigation feedback messages
LONGEST_STEP = 0.5  # seconds; a stalled process does not make the robot jump
EXECUTOR_THREADS = 4
_MARKER_TYPES = {"box": Marker.CUBE, "arrow": Marker.ARROW, "text": Marker.TEXT_VIEW_FACING}


class WorldNode(Node):
    def __init__(self) -> None:
        super().__init__(NODE_NAME)
        world_file = declare_parameter(
            self, "world_file", "", f"World YAML file; empty: the package's config/{DEFAULT_WORLD_FILE}.")
        rate_hz = declare_parameter(self, "rate_hz", 15.0, "Simulation and camera frames per second.",
                                    minimum=1.0, maximum=60.0)
        seed = declare_parameter(self, "seed", 0, "Seed of every random choice (odometry, depth noise, detector).",
                                 minimum=0, maximum=2**31 - 1)
        self._render = declare_parameter(self, "render", True, "Render and publish images; false publishes none.")
        self._depth_encoding = declare_parameter(
            self, "depth_encoding", "32FC1", "Depth encoding: 32FC1 (metres, NaN invalid) or 16UC1 (mm, 0 invalid).")
        if self._depth_encoding not in ("32FC1", "16UC1"):
            raise ConfigurationError("depth_encoding must be 32FC1 or 16UC1")
        self._publish_detections = declare_parameter(
            self, "ground_truth_detections", True, "Publish ground-truth detections on camera/detections.")
        noise = DetectorNoise(
            box_noise=declare_parameter(self, "detection_box_noise", 2.0,
                                        "Std. dev. (pixels) of each box edge.", minimum=0.0, maximum=100.0),
            miss_probability=declare_parameter(self, "detection_miss_probability", 0.05,
                                               "Probability of missing a visible object.", minimum=0.0, maximum=1.0),
            false_positives_per_frame=declare_parameter(
                self, "detection_false_positives", 0.02, "Mean number of false detections per frame.",
                minimum=0.0, maximum=20.0),
            minimum_visible_fraction=declare_parameter(
                self, "detection_minimum_visible_fraction", 0.3,
                "Share of an object's silhouette that must be visible for a detection.", minimum=0.0, maximum=1.0),
        )
        segment = declare_parameter(
            self, "detection_masks", True,
            "Give each ground-truth detection its instance mask, as a segmenting detector (YOLO-seg) does.")
        report_folder = declare_parameter(
            self, "report_folder", "", "Folder for ground_truth.json (rewritten on changes and at exit); empty: none.")
        self._world_frame = declare_parameter(self, "world_frame", "map", "Fixed frame of poses and markers.")
        self._camera_frame = declare_parameter(self, "camera_frame", "camera_color_optical_frame",
                                               "frame_id of the images and detections (optical frame).")
        self._base_frame = declare_parameter(self, "base_frame", "base_link", "child_frame_id of odom.")
        self._navigation_timeout = declare_parameter(
            self, "navigation_timeout", 300.0, "Seconds before a navigation goal ends with TIMEOUT.",
            minimum=1.0, maximum=86400.0)
        self._log_period = declare_parameter(self, "log_period", 10.0,
                                             "Seconds between two status log lines; 0 disables them.",
                                             minimum=0.0, maximum=3600.0)

        path = config_path(world_file, DEFAULT_WORLD_FILE)
        self._world = World(load_world(path), seed=seed, detector_noise=noise, segment=segment)
        self._max_speed = self._world.description.robot.limits.max_linear_speed
        self._lock = threading.Lock()
        self._report_path = Path(report_folder).expanduser() / GROUND_TRUTH_FILE if report_folder else None
        self._written_version = -1
        self._marker_version = -1
        self._closing = threading.Event()
        self._running_goals = 0
        self._goals_done = threading.Condition()

        camera = self._world.camera
        self._camera_info = camera_info_message(camera.width, camera.height, camera.fx, camera.fy, camera.cx,
                                                camera.cy)
        self._color_publisher = self.create_publisher(Image, "camera/color/image_raw", SENSOR_DATA)
        self._depth_publisher = self.create_publisher(Image, "camera/depth/image_raw", SENSOR_DATA)
        self._info_publisher = self.create_publisher(CameraInfo, "camera/color/camera_info", SENSOR_DATA)
        self._camera_pose_publisher = self.create_publisher(PoseStamped, "camera/camera_pose", SENSOR_DATA)
        self._detections_publisher = self.create_publisher(DetectionArray, "camera/detections", SENSOR_DATA)
        self._robot_pose_publisher = self.create_publisher(PoseStamped, "robot_pose", SENSOR_DATA)
        self._odometry_publisher = self.create_publisher(Odometry, "odom", SENSOR_DATA)
        self._marker_publisher = self.create_publisher(MarkerArray, "world_markers", LATCHED)

        servers = ReentrantCallbackGroup()
        self._navigation = navigate_to_pose_type()
        self._action_server = ActionServer(
            self, self._navigation, "navigate_to_pose", execute_callback=self._navigate,
            goal_callback=lambda _goal: GoalResponse.ACCEPT, cancel_callback=lambda _goal: CancelResponse.ACCEPT,
            callback_group=servers,
        )
        self.create_service(Grasp, "~/grasp", self._grasp, callback_group=servers)
        self._last_tick: Time | None = None
        self._frames, self._frame_seconds, self._last_log = 0, 0.0, time.monotonic()
        self._publish_markers()
        self._write_ground_truth()
        self._period = 1.0 / rate_hz
        self._loop = threading.Thread(target=self._simulate, name="world-simulation", daemon=True)
        self._loop.start()
        self.get_logger().info(
            f"world '{path.name}' ({len(self._world.objects)} objects, waypoints "
            f"{', '.join(w.name for w in self._world.house.waypoints)}) at {rate_hz:g} Hz, "
            f"render {'on' if self._render else 'off'}, ground-truth detections "
            f"{'on' if self._publish_detections else 'off'}; navigation serves {navigation_interface_name()}"
        )

    # --- the simulation loop ----------------------------------------------------------------------

    def _simulate(self) -> None:
        """The simulation thread: one tick every period, on the wall clock, until the node closes.

        A thread of its own rather than an executor timer: its life ends in destroy_node, after the
        executor has stopped, so no tick can run into publishers being destroyed.
        """
        next_tick = time.monotonic()
        while not self._closing.is_set():
            try:
                self._tick()
            except Exception:  # one bad frame must not end the simulation for the node's life
                if self._closing.is_set() or not self.context.ok():
                    return
                self.get_logger().error(f"simulation step failed:\n{traceback.format_exc()}",
                                        throttle_duration_sec=5.0)
            next_tick = max(next_tick + self._period, time.monotonic())
            self._closing.wait(max(next_tick - time.monotonic(), 0.0))

    def _tick(self) -> None:
        now = self.get_clock().now()
        dt = 0.0 if self._last_tick is None else min((now - self._last_tick).nanoseconds * 1e-9, LONGEST_STEP)
        self._last_tick = now
        started = time.perf_counter()
        with self._lock:
            world = self._world
            fired = world.step(dt)
            frame = world.render() if self._render else None
            detections = world.detect(frame) if self._publish_detections else None
            camera_pose = world.camera_pose()
            estimate = world.estimated_pose
            velocity = (world.odometry.linear_velocity, world.odometry.angular_velocity)
        stamp = now.to_msg()
        camera_header = Header(stamp=stamp, frame_id=self._camera_frame)
        world_header = Header(stamp=stamp, frame_id=self._world_frame)
        if frame is not None:
            self._color_publisher.publish(array_to_image(frame.color, "rgb8", camera_header))
            self._depth_publisher.publish(array_to_image(self._encode_depth(frame.depth), self._depth_encoding,
                                                         camera_header))
        self._camera_info.header = camera_header
        self._info_publisher.publish(self._camera_info)
        self._camera_pose_publisher.publish(PoseStamped(header=world_header, pose=pose_to_message(camera_pose)))
        if detections is not None:
            self._detections_publisher.publish(detections_to_message(detections, camera_header))
        robot_pose = _planar_pose(estimate.x, estimate.y, estimate.yaw)
        self._robot_pose_publisher.publish(PoseStamped(header=world_header, pose=robot_pose))
        odometry = Odometry(header=world_header, child_frame_id=self._base_frame)
        odometry.pose.pose = robot_pose
        odometry.twist.twist.linear = Vector3(x=velocity[0])
        odometry.twist.twist.angular = Vector3(z=velocity[1])
        self._odometry_publisher.publish(odometry)
        for event in fired:
            self.get_logger().info(f"scenario: {event.name} ({event.action} '{event.object_id}' "
                                   f"{_point_text(event.source)} -> {_point_text(event.destination)})")
        self._publish_markers()
        self._write_ground_truth()
        self._frames += 1
        self._frame_seconds += time.perf_counter() - started
        self._log_status()

    def _encode_depth(self, depth: np.ndarray) -> np.ndarray:
        if self._depth_encoding == "32FC1":
            return depth
        millimetres = np.nan_to_num(depth * 1000.0, nan=0.0)
        return np.clip(millimetres, 0, 65535).astype(np.uint16)

    def _log_status(self) -> None:
        elapsed = time.monotonic() - self._last_log
        if self._log_period <= 0.0 or elapsed < self._log_period:
            return
        with self._lock:
            truth, estimate = self._world.true_pose, self._world.estimated_pose
            room = self._world.house.room_at(truth.x, truth.y)
        error = math.hypot(truth.x - estimate.x, truth.y - estimate.y)
        self.get_logger().info(
            f"robot at ({truth.x:.2f}, {truth.y:.2f}, {math.degrees(truth.yaw):.0f} deg) in "
            f"{room.name if room else 'no room'}, estimate {100 * error:.1f} cm off; {self._frames / elapsed:.1f} Hz, "
            f"{1000 * self._frame_seconds / max(self._frames, 1):.1f} ms per tick"
        )
        self._frames, self._frame_seconds, self._last_log = 0, 0.0, time.monotonic()

    # --- navigation -------------------------------------------------------------------------------

    def _navigate(self, goal_handle) -> object:
        with self._goals_done:
            self._running_goals += 1
        try:
            return self._run_navigation(goal_handle)
        except Exception:  # a bug must fail the goal, not leave the client waiting forever
            self.get_logger().error(f"navigation failed:\n{traceback.format_exc()}")
            if goal_handle.is_active:
                goal_handle.abort()
            return self._navigation.Result(error_code=NavigationErrorCode.UNKNOWN, error_msg="internal error")
        finally:
            with self._goals_done:
                self._running_goals -= 1
                self._goals_done.notify_all()

    def _run_navigation(self, goal_handle) -> object:
        request = goal_handle.request.pose
        position, orientation = request.pose.position, request.pose.orientation
        try:
            if request.header.frame_id not in ("", self._world_frame):
                raise InvalidInputError(f"goal frame '{request.header.frame_id}' is not '{self._world_frame}'")
            yaw = _yaw_of(orientation)
            with self._lock:
                goal = self._world.navigate_to(position.x, position.y, yaw)
                plan = goal.plan
        except InvalidInputError as error:
            self.get_logger().warning(f"navigation goal refused: {error}")
            goal_handle.abort()
            return self._navigation.Result(error_code=NavigationErrorCode.UNKNOWN, error_msg=str(error))
        via = f" via {', '.join(plan.nodes)}" if plan.nodes else ""
        self.get_logger().info(
            f"navigating to ({position.x:.2f}, {position.y:.2f}){via}, {plan.length:.1f} m"
            + ("" if plan.reachable else "; the goal is off the graph: last leg straight"))
        started = time.monotonic()
        while True:
            time.sleep(FEEDBACK_PERIOD)
            if self._closing.is_set():
                goal_handle.abort()
                return self._navigation.Result(error_code=NavigationErrorCode.UNKNOWN,
                                               error_msg="world shutting down")
            if goal_handle.is_cancel_requested:
                with self._lock:
                    self._world.cancel_navigation(goal.id)
                goal_handle.canceled()
                self.get_logger().info("navigation canceled")
                return self._navigation.Result(error_code=NavigationErrorCode.CANCELED, error_msg="canceled")
            with self._lock:
                state = goal.state
                estimate = self._world.estimated_pose
                remaining = self._world.distance_remaining() if state is NavigationState.ACTIVE else 0.0
                elapsed_simulated = self._world.time - goal.started
            if state is NavigationState.ARRIVED:
                goal_handle.succeed()
                self.get_logger().info(f"arrived at ({estimate.x:.2f}, {estimate.y:.2f}) after "
                                       f"{elapsed_simulated:.1f} s")
                return self._navigation.Result(error_code=NavigationErrorCode.NONE)
            if state is not NavigationState.ACTIVE:
                goal_handle.abort()
                return self._navigation.Result(error_code=NavigationErrorCode.UNKNOWN,
                                             error_msg=f"goal {state.value} by a newer goal")
            if time.monotonic() - started > self._navigation_timeout:
                with self._lock:
                    self._world.cancel_navigation(goal.id)
                goal_handle.abort()
                message = f"not there after {self._navigation_timeout:g} s"
                self.get_logger().warning(f"navigation timed out: {message}")
                return self._navigation.Result(error_code=NavigationErrorCode.TIMEOUT, error_msg=message)
            feedback = self._navigation.Feedback(distance_remaining=float(remaining))
            feedback.current_pose = PoseStamped(
                header=Header(stamp=self.get_clock().now().to_msg(), frame_id=self._world_frame),
                pose=_planar_pose(estimate.x, estimate.y, estimate.yaw))
            feedback.navigation_time = _duration(time.monotonic() - started)
            feedback.estimated_time_remaining = _duration(remaining / self._max_speed)
            goal_handle.publish_feedback(feedback)

    # --- the gripper --------------------------------------------------------------------------------

    def _grasp(self, request: Grasp.Request, response: Grasp.Response) -> Grasp.Response:
        target = (request.target.x, request.target.y, request.target.z)
        try:
            with self._lock:
                if request.operation == Grasp.Request.PICK:
                    result = self._world.pick(request.class_name, target)
                elif request.operation == Grasp.Request.PLACE:
                    result = self._world.place(target if all(math.isfinite(v) for v in target[:2]) else None)
                else:
                    result = None
        except Exception:  # a bug must answer the call, not leave the client waiting
            self.get_logger().error(f"grasp failed:\n{traceback.format_exc()}")
            response.success, response.message = False, "internal error in the simulated gripper"
            return response
        if result is None:
            response.success = False
            response.message = f"unknown operation {request.operation}; use PICK ({Grasp.Request.PICK}) or " \
                               f"PLACE ({Grasp.Request.PLACE})"
        else:
            response.success, response.message, response.object_id = result.success, result.message, result.object_id
        log = self.get_logger().info if response.success else self.get_logger().warning
        log(f"grasp: {response.message}")
        return response

    # --- markers and ground truth -------------------------------------------------------------------

    def _publish_markers(self) -> None:
        with self._lock:
            if self._world.version == self._marker_version:
                return
            self._marker_version = self._world.version
            items = world_markers(self._world)
        header = Header(stamp=self.get_clock().now().to_msg(), frame_id=self._world_frame)
        markers = [Marker(header=header, action=Marker.DELETEALL)]
        markers += [_marker(item, index, header) for index, item in enumerate(items)]
        self._marker_publisher.publish(MarkerArray(markers=markers))

    def _write_ground_truth(self, force: bool = False) -> None:
        if self._report_path is None:
            return
        with self._lock:
            if self._world.version == self._written_version and not force:
                return
            self._written_version = self._world.version
            truth = self._world.ground_truth()
        # The wall-clock stamp of this version (the clock the camera frames carry), so a reader can
        # tell which version was in force when an anchor last saw its object.
        truth["stamp"] = self.get_clock().now().nanoseconds * 1e-9
        try:
            self._report_path.parent.mkdir(parents=True, exist_ok=True)
            temporary = self._report_path.with_suffix(".json.tmp")
            temporary.write_text(json.dumps(truth, indent=1), encoding="utf-8")
            os.replace(temporary, self._report_path)
        except OSError as error:
            self.get_logger().error(f"cannot write {self._report_path}: {error}", throttle_duration_sec=30.0)

    def destroy_node(self) -> None:
        # Stop the simulation thread, and let running goals (they poll _closing) end, before the
        # publishers and the action server go away.
        self._closing.set()
        self._loop.join(timeout=5.0)
        with self._goals_done:
            self._goals_done.wait_for(lambda: self._running_goals == 0, timeout=2.0 * FEEDBACK_PERIOD + 1.0)
        self._write_ground_truth(force=True)
        self._action_server.destroy()
        super().destroy_node()


def _yaw_of(orientation: Quaternion) -> float | None:
    """Heading of a goal's orientation; None for the all-zero quaternion, which means 'any heading'."""
    values = (orientation.x, orientation.y, orientation.z, orientation.w)
    if not all(math.isfinite(value) for value in values):
        raise InvalidInputError(f"goal orientation {values} is not finite")
    if math.fsum(value * value for value in values) < 1e-12:
        return None
    x, y, z, w = values
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def _planar_pose(x: float, y: float, yaw: float) -> Pose:
    qx, qy, qz, qw = yaw_to_quaternion(yaw)
    return Pose(position=Point(x=float(x), y=float(y), z=0.0), orientation=Quaternion(x=qx, y=qy, z=qz, w=qw))


def _duration(seconds: float) -> Duration:
    stamp = seconds_to_stamp(max(seconds, 0.0))
    return Duration(sec=stamp.sec, nanosec=stamp.nanosec)


def _marker(item: MarkerItem, index: int, header: Header) -> Marker:
    marker = Marker(header=header, ns=item.namespace, id=index, type=_MARKER_TYPES[item.kind], action=Marker.ADD,
                    text=item.text)
    marker.pose.position = Point(x=float(item.center[0]), y=float(item.center[1]), z=float(item.center[2]))
    qx, qy, qz, qw = yaw_to_quaternion(item.yaw)
    marker.pose.orientation = Quaternion(x=qx, y=qy, z=qz, w=qw)
    marker.scale = Vector3(x=float(item.size[0]), y=float(item.size[1]), z=float(item.size[2]))
    marker.color = ColorRGBA(r=float(item.color[0]), g=float(item.color[1]), b=float(item.color[2]),
                             a=float(item.color[3]))
    return marker


def _point_text(point: Sequence[float] | None) -> str:
    return "nowhere" if point is None else "(" + ", ".join(f"{value:.2f}" for value in point) + ")"


def main(argv: Sequence[str] | None = None) -> int:
    return run_node(WorldNode, argv, threads=EXECUTOR_THREADS)


if __name__ == "__main__":
    raise SystemExit(main())
