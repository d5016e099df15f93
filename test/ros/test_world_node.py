"""The world node as a real process: one stamp per frame, a navigation goal driven to the end, a grasp."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from geometry_msgs.msg import Point, PoseStamped
from rclpy.action import ActionClient
from sensor_msgs.msg import CameraInfo, Image

from merlin2_sailor.resources import config_file
from merlin2_sailor.ros.conversions import depth_to_metres, detections_from_message, image_to_array
from merlin2_sailor.ros.navigation_interface import NavigationErrorCode, navigate_to_pose_type
from merlin2_sailor.ros.qos import SENSOR_DATA
from merlin2_sailor_demos.world import load_world
from merlin2_sailor_interfaces.msg import DetectionArray
from merlin2_sailor_interfaces.srv import Grasp

pytestmark = pytest.mark.ros

NAMESPACE = "/sim"
CAMERA_TOPICS = {
    "color": (Image, f"{NAMESPACE}/camera/color/image_raw"),
    "depth": (Image, f"{NAMESPACE}/camera/depth/image_raw"),
    "info": (CameraInfo, f"{NAMESPACE}/camera/color/camera_info"),
    "pose": (PoseStamped, f"{NAMESPACE}/camera/camera_pose"),
    "detections": (DetectionArray, f"{NAMESPACE}/camera/detections"),
}


def _stamp(message) -> tuple[int, int]:
    return (message.header.stamp.sec, message.header.stamp.nanosec)


#: How long a service or action answer may take: the world node renders and detects 15 frames a
#: second on the same 2 cores, and under a parallel load a goal once took over 10 s to be accepted.
ANSWER_DEADLINE = 30.0


def _wait(probe, future, timeout: float = ANSWER_DEADLINE):
    assert probe.wait_for(future.done, timeout), "no answer in time"
    return future.result()


def _collect_one_frame(probe) -> dict:
    """Subscribe to every camera topic at once; return the messages of the first stamp seen on all."""
    received: dict[str, dict] = {name: {} for name in CAMERA_TOPICS}

    def common() -> set:
        return set.intersection(*(set(messages) for messages in received.values()))

    with probe.listener() as listener:
        for name, (kind, topic) in CAMERA_TOPICS.items():
            listener.create_subscription(kind, topic, lambda m, n=name: received[n].setdefault(_stamp(m), m),
                                         SENSOR_DATA)
        probe.wait_for(lambda: bool(common()), timeout=20.0)
    stamps = common()
    assert stamps, {name: len(messages) for name, messages in received.items()}
    stamp = min(stamps)
    return {name: messages[stamp] for name, messages in received.items()}


def test_frames_navigation_and_grasp(ros_probe, node_process, tmp_path) -> None:
    house = load_world(config_file("worlds/house.yaml")).house
    process = node_process("world", "--ros-args", "-r", f"__ns:={NAMESPACE}", "-p", "rate_hz:=10.0",
                           "-p", "detection_miss_probability:=0.0", "-p", f"report_folder:={tmp_path}")
    try:
        assert ros_probe.wait_for_node(f"{NAMESPACE}/world"), process.text

        # One frame: colour, depth, intrinsics, camera pose and detections with one stamp.
        frame = _collect_one_frame(ros_probe)
        color, depth = image_to_array(frame["color"]), image_to_array(frame["depth"])
        assert color.shape == (480, 640, 3) and frame["color"].encoding == "rgb8"
        metres = depth_to_metres(depth, frame["depth"].encoding)
        assert 0.5 < np.nanmedian(metres) < 6.0
        assert frame["info"].k[0] == pytest.approx(525.0) and frame["pose"].header.frame_id == "map"
        detections = detections_from_message(frame["detections"])
        assert "cup" in {detection.class_name for detection in detections}  # the kitchen table's mugs

        # Pick the red mug from the kitchen waypoint (1.2 m away), as a manipulation behaviour would.
        grasp = ros_probe.node.create_client(Grasp, f"{NAMESPACE}/world/grasp")
        assert grasp.wait_for_service(timeout_sec=20.0)
        picked = _wait(ros_probe, grasp.call_async(Grasp.Request(operation=Grasp.Request.PICK, class_name="cup",
                                                                  target=_point(2.1, 2.1))))
        assert picked.success and picked.object_id == "red_mug", picked.message

        # Drive to the living room with it, through Nav2's type where nav2_msgs is built.
        NavigateToPose = navigate_to_pose_type()  # noqa: N806 - a message type
        client = ActionClient(ros_probe.node, NavigateToPose, f"{NAMESPACE}/navigate_to_pose")
        assert client.wait_for_server(timeout_sec=20.0)
        target = house.waypoint("living_room").pose
        goal = NavigateToPose.Goal()
        goal.pose.header.frame_id = "map"
        goal.pose.pose.position.x, goal.pose.pose.position.y = target.x, target.y
        goal.pose.pose.orientation.z, goal.pose.pose.orientation.w = math.sin(target.yaw / 2), math.cos(target.yaw / 2)
        feedback = []
        handle = _wait(ros_probe, client.send_goal_async(goal, feedback_callback=feedback.append))
        assert handle.accepted
        result = _wait(ros_probe, handle.get_result_async(), 25.0).result
        assert result.error_code == NavigationErrorCode.NONE, result.error_msg
        assert feedback and feedback[0].feedback.distance_remaining > 1.0
        (pose,) = ros_probe.collect(PoseStamped, f"{NAMESPACE}/robot_pose", 1, SENSOR_DATA)
        assert math.hypot(pose.pose.position.x - target.x, pose.pose.position.y - target.y) < 0.1

        # A goal outside the house fails cleanly; then put the mug down ahead of the robot.
        goal.pose.pose.position.x = 50.0
        bad = _wait(ros_probe, _wait(ros_probe, client.send_goal_async(goal)).get_result_async())
        assert bad.result.error_code == NavigationErrorCode.UNKNOWN and "outside the house" in bad.result.error_msg
        placed = _wait(ros_probe, grasp.call_async(Grasp.Request(operation=Grasp.Request.PLACE,
                                                                  target=_point(math.nan, math.nan))))
        assert placed.success, placed.message

        # A goal cancelled on the way ends CANCELED.
        hall = house.waypoint("hall").pose
        goal.pose.pose.position.x, goal.pose.pose.position.y = hall.x, hall.y
        handle = _wait(ros_probe, client.send_goal_async(goal))
        ros_probe.wait_for(lambda: False, timeout=1.0)
        _wait(ros_probe, handle.cancel_goal_async())
        cancelled = _wait(ros_probe, handle.get_result_async()).result
        assert cancelled.error_code == NavigationErrorCode.CANCELED
        client.destroy()
    finally:
        assert process.stop() == 0, process.text
    assert "Traceback" not in process.text
    truth = json.loads((tmp_path / "ground_truth.json").read_text())
    red_mug = next(item for item in truth["objects"] if item["id"] == "red_mug")
    assert red_mug["room"] == "living_room" and not red_mug["carried"]
    assert truth["robot"]["arrivals"] == 1 and truth["robot"]["visited"] == ["living_room"]
    # The version is stamped on the camera's clock, so a reader can tell which version an anchor's
    # last sighting belongs to: after the first frame, before the end.
    first_frame = frame["color"].header.stamp.sec + frame["color"].header.stamp.nanosec * 1e-9
    assert first_frame < truth["stamp"] < first_frame + 120.0


def test_a_scenario_world_file_extends_the_house(ros_probe, node_process, tmp_path) -> None:
    process = node_process("world", "--ros-args", "-r", f"__ns:={NAMESPACE}", "-p", "rate_hz:=5.0",
                           "-p", "world_file:=worlds/scenarios/crowded_shelf.yaml", "-p", f"report_folder:={tmp_path}")
    try:
        # A pose from the simulation loop: the node is past its start (and its log line).
        assert ros_probe.collect(PoseStamped, f"{NAMESPACE}/robot_pose", 1, SENSOR_DATA), process.text
    finally:
        assert process.stop() == 0, process.text
    ids = {item["id"] for item in json.loads((tmp_path / "ground_truth.json").read_text())["objects"]}
    assert {f"shelf_book_{n}" for n in range(1, 8)} <= ids and "book_1" not in ids and "red_mug" in ids
    assert "world 'crowded_shelf.yaml' (27 objects" in process.text


def _point(x: float, y: float) -> Point:
    return Point(x=float(x), y=float(y), z=0.0)


def test_a_bad_world_file_stops_the_node_with_a_clear_message(node_process, tmp_path) -> None:
    broken = tmp_path / "broken.yaml"
    broken.write_text("house: {rooms: []}\ntextures: {}\nobjects: []\n")
    process = node_process("world", "--ros-args", "-p", f"world_file:={broken}")
    process.process.wait(timeout=30.0)
    assert process.stop() == 2
    assert "broken.yaml" in process.text and "Traceback" not in process.text
