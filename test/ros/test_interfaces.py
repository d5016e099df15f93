"""merlin2_sailor_interfaces: every type imports and survives serialisation unchanged."""

from __future__ import annotations

from pathlib import Path

import pytest
from rclpy.serialization import deserialize_message, serialize_message

from merlin2_sailor_interfaces import action, msg, srv

# Every type defined in the interfaces package's sources, so a new .msg or .srv is tested at once.
INTERFACES_SOURCE = Path(__file__).resolve().parents[2] / "merlin2_sailor_interfaces"
MESSAGE_TYPES = [getattr(msg, path.stem) for path in sorted(INTERFACES_SOURCE.glob("msg/*.msg"))]
SERVICE_TYPES = [getattr(srv, path.stem) for path in sorted(INTERFACES_SOURCE.glob("srv/*.srv"))]
ACTION_TYPES = [getattr(action, path.stem) for path in sorted(INTERFACES_SOURCE.glob("action/*.action"))]


def test_the_interfaces_cover_detections_percepts_anchors_and_the_knowledge_base() -> None:
    names = {message_type.__name__ for message_type in MESSAGE_TYPES + SERVICE_TYPES}
    assert {"Detection", "DetectionArray", "Percept", "PerceptArray", "Anchor", "AnchorArray",
            "GetAnchors", "FindAnchor", "ForgetAnchor", "PddlProposition", "KnowledgeChanges",
            "ApplyChanges", "GetPropositions", "UpdateProposition",
            "DeleteAllPropositions"} <= names


def sample_detection() -> msg.Detection:
    detection = msg.Detection(class_id=47, class_name="cup", score=0.83, id="12")
    detection.bbox.center.position.x, detection.bbox.center.position.y = 320.5, 240.25
    detection.bbox.size.x, detection.bbox.size.y = 40.0, 60.0
    detection.bbox3d.frame_id = "map"
    detection.bbox3d.size.z = 0.12
    detection.mask.height, detection.mask.width = 480, 640
    detection.mask.data = [msg.Point2D(x=1.0, y=2.0), msg.Point2D(x=3.0, y=4.0)]
    return detection


def sample_anchor() -> msg.Anchor:
    anchor = msg.Anchor(symbol="cup_3", class_name="cup", state=msg.Anchor.STATE_CONFIRMED,
                        confidence=0.9, times_seen=17, last_tracker_id="12")
    anchor.position.x, anchor.position.y, anchor.position.z = 1.5, -2.0, 0.8
    anchor.first_seen.sec, anchor.last_seen.sec = 10, 25
    return anchor


@pytest.mark.parametrize("message_type", MESSAGE_TYPES, ids=lambda t: t.__name__)
def test_every_message_round_trips_through_serialisation(message_type: type) -> None:
    original = message_type()
    assert deserialize_message(serialize_message(original), message_type) == original


def test_filled_messages_round_trip_with_all_fields() -> None:
    array = msg.DetectionArray(detections=[sample_detection(), msg.Detection(class_name="dog")])
    array.header.frame_id = "camera_color_optical_frame"
    array.header.stamp.sec, array.header.stamp.nanosec = 5, 500
    assert deserialize_message(serialize_message(array), msg.DetectionArray) == array

    anchors = msg.AnchorArray(anchors=[sample_anchor()])
    assert deserialize_message(serialize_message(anchors), msg.AnchorArray) == anchors

    percept = msg.Percept(class_name="cup", class_id=47, score=0.9, tracker_id="")
    percept.crop.height, percept.crop.width, percept.crop.encoding = 2, 1, "rgb8"
    percept.crop.step, percept.crop.data = 3, bytes(range(6))
    restored = deserialize_message(serialize_message(msg.PerceptArray(percepts=[percept])), msg.PerceptArray)
    assert restored.percepts[0] == percept


def test_anchor_states_are_the_lifecycle_in_order() -> None:
    states = [msg.Anchor.STATE_TENTATIVE, msg.Anchor.STATE_CONFIRMED,
              msg.Anchor.STATE_MISSING, msg.Anchor.STATE_FORGOTTEN]
    assert states == [0, 1, 2, 3]


@pytest.mark.parametrize("service_type", SERVICE_TYPES, ids=lambda t: t.__name__)
def test_every_service_request_and_response_round_trips(service_type: type) -> None:
    for part in (service_type.Request, service_type.Response):
        original = part()
        assert deserialize_message(serialize_message(original), part) == original
    response = srv.FindAnchor.Response(found=True, anchor=sample_anchor(), message="")
    assert deserialize_message(serialize_message(response), srv.FindAnchor.Response) == response


def test_the_interfaces_cover_navigation_and_running_plan_steps() -> None:
    assert {action_type.__name__ for action_type in ACTION_TYPES} >= {"NavigateToPose", "RunPddlAction"}


@pytest.mark.parametrize("action_type", ACTION_TYPES, ids=lambda t: t.__name__)
def test_every_action_goal_result_and_feedback_round_trips(action_type: type) -> None:
    for part in (action_type.Goal, action_type.Result, action_type.Feedback):
        original = part()
        assert deserialize_message(serialize_message(original), part) == original
    # The wrapper messages rclpy's action client and server exchange.
    for part in (action_type.Impl.SendGoalService.Request, action_type.Impl.GetResultService.Response,
                 action_type.Impl.FeedbackMessage):
        original = part()
        assert deserialize_message(serialize_message(original), part) == original


def test_a_filled_plan_step_goal_and_result_round_trip() -> None:
    goal = action.RunPddlAction.Goal(action_name="bring", objects=["cup_1", "kitchen", "bedroom"])
    assert deserialize_message(serialize_message(goal), action.RunPddlAction.Goal) == goal
    result = action.RunPddlAction.Result(outcome="aborted", message="could not pick cup_1")
    assert deserialize_message(serialize_message(result), action.RunPddlAction.Result) == result
    navigation = action.NavigateToPose.Goal()
    navigation.pose.header.frame_id = "map"
    navigation.pose.pose.position.x, navigation.pose.pose.orientation.w = 2.0, 1.0
    assert deserialize_message(serialize_message(navigation), action.NavigateToPose.Goal) == navigation
