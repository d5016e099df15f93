"""Anchors and anchor events to merlin2_sailor_interfaces messages, and their RViz markers.

The node converts :class:`~merlin2_sailor.anchoring.anchor_view.AnchorView` copies (taken under its
lock, so another thread's frame cannot change an anchor half-way through its message); a live
:class:`~merlin2_sailor.anchoring.anchor.Anchor` has the same attributes and converts the same way.
"""

from __future__ import annotations

from collections.abc import Sequence
from types import MappingProxyType

from diagnostic_msgs.msg import KeyValue
from std_msgs.msg import Header
from visualization_msgs.msg import Marker, MarkerArray

from merlin2_sailor.anchoring.anchor import Anchor, AnchorState
from merlin2_sailor.anchoring.anchor_view import AnchorView
from merlin2_sailor.anchoring.events import AnchorEvent, AnchorEventKind
from merlin2_sailor.ros.conversions.sensors import seconds_to_stamp
from merlin2_sailor_interfaces.msg import Anchor as AnchorMessage
from merlin2_sailor_interfaces.msg import AnchorArray, AnchorEventArray
from merlin2_sailor_interfaces.msg import AnchorEvent as AnchorEventMessage

STATE_TO_MESSAGE = MappingProxyType({
    AnchorState.TENTATIVE: AnchorMessage.STATE_TENTATIVE,
    AnchorState.CONFIRMED: AnchorMessage.STATE_CONFIRMED,
    AnchorState.MISSING: AnchorMessage.STATE_MISSING,
    AnchorState.FORGOTTEN: AnchorMessage.STATE_FORGOTTEN,
})
STATE_FROM_MESSAGE = MappingProxyType({value: key for key, value in STATE_TO_MESSAGE.items()})
EVENT_KIND_TO_MESSAGE = MappingProxyType({
    AnchorEventKind.ACQUIRED: AnchorEventMessage.KIND_ACQUIRED,
    AnchorEventKind.REACQUIRED: AnchorEventMessage.KIND_REACQUIRED,
    AnchorEventKind.CONFIRMED: AnchorEventMessage.KIND_CONFIRMED,
    AnchorEventKind.MISSING: AnchorEventMessage.KIND_MISSING,
    AnchorEventKind.FORGOTTEN: AnchorEventMessage.KIND_FORGOTTEN,
    AnchorEventKind.RETRACTED: AnchorEventMessage.KIND_RETRACTED,
    AnchorEventKind.AMBIGUOUS: AnchorEventMessage.KIND_AMBIGUOUS,
})
#: What the conversions read: a frozen view (what nodes pass) or, single-threaded, a live anchor.
AnchorLike = AnchorView | Anchor
_STATE_COLOURS = MappingProxyType({
    AnchorState.TENTATIVE: (0.9, 0.8, 0.2), AnchorState.CONFIRMED: (0.2, 0.8, 0.3),
    AnchorState.MISSING: (0.9, 0.3, 0.2), AnchorState.FORGOTTEN: (0.5, 0.5, 0.5),
})


def anchor_to_message(anchor: AnchorLike) -> AnchorMessage:
    message = AnchorMessage(
        symbol=anchor.symbol, class_name=anchor.class_name, state=STATE_TO_MESSAGE[anchor.state],
        confidence=float(anchor.confidence), times_seen=int(anchor.times_seen),
        last_tracker_id=anchor.last_tracker_id,
        indistinguishable_from=list(anchor.indistinguishable_from),
        found_by_look_alone=anchor.found_by_look_alone,
        first_seen=seconds_to_stamp(anchor.first_seen), last_seen=seconds_to_stamp(anchor.last_seen),
    )
    message.position.x, message.position.y, message.position.z = (float(v) for v in anchor.position)
    message.size.x, message.size.y, message.size.z = (float(v) for v in anchor.size)
    return message


def anchors_to_message(anchors: Sequence[AnchorLike], header: Header) -> AnchorArray:
    return AnchorArray(header=header, anchors=[anchor_to_message(anchor) for anchor in anchors])


def event_to_message(event: AnchorEvent, class_name: str) -> AnchorEventMessage:
    return AnchorEventMessage(
        stamp=seconds_to_stamp(event.stamp), kind=EVENT_KIND_TO_MESSAGE[event.kind],
        symbol=event.symbol, class_name=class_name,
        details=[KeyValue(key=str(key), value=str(value)) for key, value in event.details.items()],
    )


def events_to_message(events: Sequence[AnchorEvent], class_names: dict[str, str],
                      header: Header) -> AnchorEventArray:
    return AnchorEventArray(header=header, events=[
        event_to_message(event, class_names.get(event.symbol, "")) for event in events])


def anchor_markers(anchors: Sequence[AnchorLike], header: Header) -> MarkerArray:
    """One box and one label per anchor, coloured by state; DELETEALL first drops stale ones."""
    markers = [Marker(header=header, action=Marker.DELETEALL)]
    for index, anchor in enumerate(anchors):
        red, green, blue = _STATE_COLOURS[anchor.state]
        box = Marker(header=header, ns="anchors", id=2 * index, type=Marker.CUBE, action=Marker.ADD)
        box.pose.position.x, box.pose.position.y, box.pose.position.z = (float(v) for v in anchor.position)
        box.pose.orientation.w = 1.0
        box.scale.x, box.scale.y, box.scale.z = (max(float(v), 0.02) for v in anchor.size)
        box.color.r, box.color.g, box.color.b, box.color.a = red, green, blue, 0.4
        label = Marker(header=header, ns="anchor_labels", id=2 * index + 1, type=Marker.TEXT_VIEW_FACING,
                       action=Marker.ADD, text=f"{anchor.symbol} ({anchor.state.value})")
        label.pose.position.x, label.pose.position.y = float(anchor.position[0]), float(anchor.position[1])
        label.pose.position.z = float(anchor.position[2] + anchor.size[2] / 2.0 + 0.1)
        label.pose.orientation.w = 1.0
        label.scale.z = 0.12
        label.color.r, label.color.g, label.color.b, label.color.a = red, green, blue, 1.0
        markers.append(box)
        markers.append(label)
    return MarkerArray(markers=markers)
