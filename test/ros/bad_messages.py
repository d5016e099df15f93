"""Hypothesis strategies for malformed and hostile ROS messages, and the settings CI runs them with.

Every strategy draws whole messages, ready to publish: wrong sizes and steps, unknown encodings,
NaN / inf / huge numbers, inverted and enormous boxes, empty and absurd arrays, duplicate,
out-of-order and impossible stamps, unknown classes and names aimed at PDDL text. Sizes are capped
so a batch stays small enough to publish fast (a field may *claim* 4 billion pixels; the data
behind it is at most a few hundred kilobytes).
"""

from __future__ import annotations

import math
import os
import struct
import time

from builtin_interfaces.msg import Time
from geometry_msgs.msg import Point, PoseStamped, Vector3
from hypothesis import HealthCheck, Phase, settings
from hypothesis import strategies as st
from nav_msgs.msg import Odometry
from sensor_msgs.msg import CameraInfo, Image, PointCloud2, PointField
from std_msgs.msg import Header

from merlin2_sailor_interfaces.msg import Detection, DetectionArray, Mask, Percept, PerceptArray, Point2D

#: CI settings: few examples, no deadline (a loaded machine is slow, never wrong), the same
#: examples on every run, no example database, and no shrinking (the nodes under test keep
#: state between examples, so replaying a smaller example would not reproduce a failure anyway).
#: The long form: SAILOR_BAD_INPUT_EXAMPLES=300 (still deterministic, just more batches).
BAD_INPUT_SETTINGS = settings(
    max_examples=int(os.environ.get("SAILOR_BAD_INPUT_EXAMPLES", "10")),
    deadline=None,
    derandomize=True,
    database=None,
    phases=(Phase.explicit, Phase.generate),
    suppress_health_check=list(HealthCheck),
    print_blob=False,
)

INT32 = (-(2**31), 2**31 - 1)
UINT32 = (0, 2**32 - 1)
MAXIMUM_DATA_BYTES = 200_000

HOSTILE_NAMES = (
    "", " ", ")(:goal", "cup)(:goal (and (robot_at r1 wp1)))", "cup\n(:init (holding robot cup_9))",
    "(define (domain x))", "and", "not", "at start", "3d printer", "_", "-", "()", ";", "cup;comment", "?x",
    "Café ☕", "杯子", "💥", "\x00", "a\x00b", "cup\r\n", "CUP", "x" * 5000, "unknown_class_xyz", "wp kitchen",
    "name with spaces", "\t\n", "../../etc/passwd", "cup_", "_1", "1",
)
names = st.one_of(st.sampled_from(HOSTILE_NAMES), st.text(max_size=30))

SPECIAL_FLOATS = (math.nan, math.inf, -math.inf, 0.0, -0.0, -1.0, 1.0, 1e308, -1e308, 5e-324, 1e9, -1e9, 0.5)
floats = st.one_of(st.sampled_from(SPECIAL_FLOATS), st.floats(allow_nan=True, allow_infinity=True))
float32s = st.one_of(st.sampled_from((math.nan, math.inf, -math.inf, 0.0, -1.0, 1.0)),
                     st.floats(width=32, allow_nan=True, allow_infinity=True))
int32s = st.one_of(st.sampled_from((0, -1, 1, *INT32)), st.integers(*INT32))
sizes = st.sampled_from((0, 1, 2, 3, 7, 64, 240, 320, 480, 640, 65535, 2**31 - 1, 2**32 - 1))


def mostly(plausible: st.SearchStrategy, hostile: st.SearchStrategy) -> st.SearchStrategy:
    """Two draws in three plausible: a message must pass its first checks to reach the deeper code."""
    return st.one_of(plausible, plausible, hostile)


scores = mostly(st.floats(0.0, 1.0), floats)
pixels = mostly(st.floats(-50.0, 700.0), floats)  # box centres, near or inside a 640x480 image
extents = mostly(st.floats(0.5, 500.0), floats)  # box sizes in pixels
metres = mostly(st.floats(-20.0, 20.0), floats)
thetas = mostly(st.just(0.0), floats)
IMAGE_ENCODINGS = ("rgb8", "bgr8", "rgba8", "bgra8", "mono8", "mono16", "16UC1", "32FC1", "8UC3",
                   "", "RGB8", "yuv422", "jpeg", "64FC1", "32FC3", "rgb8)(:goal", "16SC1")


@st.composite
def stamps(draw: st.DrawFn) -> Time:
    """Now, a little late or early, a duplicate second, the epoch, the far future, or malformed."""
    now = time.time()
    kind = draw(st.sampled_from(("now", "late", "early", "epoch", "future", "negative", "bad_nanoseconds", "any")))
    if kind == "now":
        return Time(sec=int(now), nanosec=0)  # many draws share this second: duplicate stamps
    if kind == "late":
        seconds = now - draw(st.floats(0.0, 5.0))
    elif kind == "early":
        seconds = now + draw(st.floats(0.0, 5.0))
    elif kind == "epoch":
        return Time(sec=0, nanosec=0)
    elif kind == "future":
        return Time(sec=INT32[1], nanosec=999_999_999)
    elif kind == "negative":
        return Time(sec=draw(st.integers(INT32[0], -1)), nanosec=draw(st.integers(0, 999_999_999)))
    elif kind == "bad_nanoseconds":
        return Time(sec=int(now), nanosec=draw(st.integers(1_000_000_000, UINT32[1])))
    else:
        return Time(sec=draw(int32s), nanosec=draw(st.integers(*UINT32)))
    return Time(sec=int(seconds), nanosec=int((seconds % 1.0) * 1e9))


def headers(frame_ids: tuple[str, ...] = ("camera_color_optical_frame", "map")) -> st.SearchStrategy[Header]:
    return st.builds(Header, stamp=stamps(), frame_id=st.one_of(st.sampled_from(frame_ids), names))


@st.composite
def payloads(draw: st.DrawFn, claimed: int) -> bytes:
    """Bytes for a message claiming ``claimed`` bytes: none, a few, exactly (capped), or too many."""
    length = draw(st.sampled_from((0, 1, 13, min(claimed, MAXIMUM_DATA_BYTES), min(claimed + 7, MAXIMUM_DATA_BYTES))))
    fill = draw(st.sampled_from((b"\x00", b"\xff", b"\x00\x00\xc0\x7f", b"\x00\x00\x80\x7f", b"\x00\x00\x80\xff")))
    return (fill * (length // len(fill) + 1))[:length]  # zeros, 0xff, float32 NaN, +inf or -inf


@st.composite
def well_formed_images(draw: st.DrawFn) -> Image:
    """A consistent image of a size and encoding nobody expects, its pixels NaN, inf or extreme."""
    encoding = draw(st.sampled_from(("rgb8", "bgra8", "mono8", "16UC1", "32FC1")))
    height, width = draw(st.integers(1, 64)), draw(st.integers(1, 64))
    channels = {"rgb8": 3, "bgra8": 4}.get(encoding, 1)
    item = {"16UC1": 2, "32FC1": 4}.get(encoding, 1)
    step = width * channels * item
    if encoding == "32FC1":
        value = draw(st.sampled_from((math.nan, math.inf, -math.inf, -1.0, 0.0, 1e30)))
        data = struct.pack("<f", value) * (height * width)
    else:
        data = bytes([draw(st.integers(0, 255))]) * (step * height)
    return Image(header=draw(headers()), height=height, width=width, encoding=encoding, is_bigendian=0, step=step,
                 data=data)


@st.composite
def images(draw: st.DrawFn) -> Image:
    if draw(st.booleans()):
        return draw(well_formed_images())
    height, width = draw(sizes), draw(sizes)
    encoding = draw(st.sampled_from(IMAGE_ENCODINGS))
    channels_bytes = draw(st.sampled_from((1, 2, 3, 4, 8, 12)))
    step = draw(st.sampled_from((0, 1, (width * channels_bytes) % 2**32, (width * channels_bytes + 3) % 2**32,
                                 UINT32[1])))
    return Image(header=draw(headers()), height=height, width=width, encoding=encoding,
                 is_bigendian=draw(st.integers(0, 255)), step=step, data=draw(payloads(step * height)))


@st.composite
def camera_infos(draw: st.DrawFn) -> CameraInfo:
    message = CameraInfo(header=draw(headers()), width=draw(sizes), height=draw(sizes))
    message.distortion_model = draw(names)
    message.d = draw(st.lists(floats, max_size=20))
    message.k = draw(st.lists(floats, min_size=9, max_size=9))
    message.r = draw(st.lists(floats, min_size=9, max_size=9))
    message.p = draw(st.lists(floats, min_size=12, max_size=12))
    return message


def _point(draw: st.DrawFn) -> Point:
    return Point(x=draw(floats), y=draw(floats), z=draw(floats))


@st.composite
def pose_stampeds(draw: st.DrawFn) -> PoseStamped:
    message = PoseStamped(header=draw(headers(("map", "odom", "camera_color_optical_frame"))))
    message.pose.position = _point(draw)
    orientation = message.pose.orientation
    orientation.x, orientation.y, orientation.z, orientation.w = (draw(floats) for _ in range(4))
    return message


@st.composite
def odometries(draw: st.DrawFn) -> Odometry:
    pose = draw(pose_stampeds())
    message = Odometry(header=pose.header, child_frame_id=draw(names))
    message.pose.pose = pose.pose
    message.pose.covariance = draw(st.lists(floats, min_size=36, max_size=36))
    return message


@st.composite
def point_clouds(draw: st.DrawFn) -> PointCloud2:
    if draw(st.booleans()):  # organised and readable, but of the wrong size or full of NaN / inf
        height, width = draw(st.integers(2, 48)), draw(st.integers(1, 64))
        value = draw(st.sampled_from((math.nan, math.inf, -1.0, 0.0, 2.0, 1e30)))
        cloud = PointCloud2(header=draw(headers()), height=height, width=width, is_bigendian=False, point_step=12,
                            row_step=12 * width, is_dense=False, data=struct.pack("<fff", value, value, value)
                            * (height * width))
        cloud.fields = [PointField(name=name, offset=4 * k, datatype=PointField.FLOAT32, count=1)
                        for k, name in enumerate("xyz")]
        return cloud
    fields = draw(st.lists(st.builds(
        PointField, name=st.sampled_from(("x", "y", "z", "rgb", "", "X")),
        offset=st.sampled_from((0, 4, 8, 12, UINT32[1])), datatype=st.integers(0, 255),
        count=st.sampled_from((0, 1, 2, UINT32[1]))), max_size=5))
    height, width = draw(sizes), draw(sizes)
    point_step = draw(st.sampled_from((0, 1, 12, 16, UINT32[1])))
    row_step = draw(st.sampled_from((0, (point_step * width) % 2**32, UINT32[1])))
    return PointCloud2(header=draw(headers()), height=height, width=width, fields=fields,
                       is_bigendian=draw(st.booleans()), point_step=point_step, row_step=row_step,
                       data=draw(payloads(row_step * height)), is_dense=draw(st.booleans()))


@st.composite
def masks(draw: st.DrawFn) -> Mask:
    points = draw(st.lists(st.builds(Point2D, x=floats, y=floats), max_size=6))
    # Never more than 2**31 pixels claimed short of an absurd 2**62: a mask between the two would
    # really be allocated by a node that does not refuse it (gigabytes on a shared machine).
    height, width = draw(st.sampled_from(((0, 0), (-1, 5), (1, 1), (480, 640), (100, 100), (2**31 - 1, 2**31 - 1))))
    return Mask(height=height, width=width, data=points)


def draw_box(draw: st.DrawFn, box) -> None:
    """Fill a BoundingBox2D message with any centre, rotation and size, however wrong."""
    box.center.position.x, box.center.position.y, box.center.theta = draw(pixels), draw(pixels), draw(thetas)
    box.size.x, box.size.y = draw(extents), draw(extents)


@st.composite
def detections(draw: st.DrawFn) -> Detection:
    message = Detection(class_id=draw(int32s), class_name=draw(names), score=draw(scores), id=draw(names))
    draw_box(draw, message.bbox)
    if draw(st.booleans()):
        message.mask = draw(masks())
    return message


@st.composite
def detection_arrays(draw: st.DrawFn) -> DetectionArray:
    return DetectionArray(header=draw(headers()), detections=draw(st.lists(detections(), max_size=8)))


@st.composite
def percepts(draw: st.DrawFn) -> Percept:
    message = Percept(class_name=draw(names), class_id=draw(int32s), score=draw(scores), tracker_id=draw(names),
                      stamp=draw(stamps()), position=Point(x=draw(metres), y=draw(metres), z=draw(metres)),
                      size=Vector3(x=draw(extents), y=draw(extents), z=draw(extents)))
    draw_box(draw, message.bbox)
    if draw(st.booleans()):
        message.crop = draw(images())
    return message


@st.composite
def percept_arrays(draw: st.DrawFn) -> PerceptArray:
    return PerceptArray(header=draw(headers(("map", "odom", ""))), percepts=draw(st.lists(percepts(), max_size=6)))
