"""Perceptual-layer messages to the core's objects and back.

Detections and percepts (merlin2_sailor_interfaces), camera intrinsics (CameraInfo), camera poses
(PoseStamped, Odometry, TransformStamped), organised point clouds (PointCloud2), colour images as
the detectors take them, and the RViz markers of a frame's percepts. Reading a message validates
it: a malformed message raises InvalidInputError with the reason, which the node logs before
dropping it, so garbage from the network never reaches the geometry code.
"""

from __future__ import annotations

import colorsys
import math
import zlib
from collections.abc import Sequence

import numpy as np
from geometry_msgs.msg import Point, Quaternion, TransformStamped, Vector3
from geometry_msgs.msg import Pose as PoseMessage
from nav_msgs.msg import Odometry
from sensor_msgs.msg import CameraInfo, Image, PointCloud2, PointField
from std_msgs.msg import ColorRGBA, Header
from visualization_msgs.msg import Marker, MarkerArray

from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.percept import BoundingBox2D, Percept
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import InvalidInputError
from merlin2_sailor.perception.colour_histogram import COLOUR_BINS
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor.ros.conversions.sensors import array_to_image, image_to_array, seconds_to_stamp, stamp_to_seconds
from merlin2_sailor_interfaces.msg import Detection as DetectionMessage
from merlin2_sailor_interfaces.msg import DetectionArray, Mask, PerceptArray, Point2D
from merlin2_sailor_interfaces.msg import Percept as PerceptMessage

#: Colour encodings a detector can take, and how to reorder their channels into RGB.
_TO_RGB_CHANNELS = {"rgb8": (0, 1, 2), "rgba8": (0, 1, 2), "bgr8": (2, 1, 0), "bgra8": (2, 1, 0)}

#: Largest rotation (radians) of a 2D box still read as axis-aligned: detectors write exactly 0.
_AXIS_ALIGNED_TOLERANCE = 1e-6

# Marker namespaces: boxes and labels are separate so RViz can toggle them independently.
BOX_MARKER_NAMESPACE = "percept_boxes"
LABEL_MARKER_NAMESPACE = "percept_labels"
_MINIMUM_MARKER_EXTENT = 0.01  # metres; a zero scale makes RViz warn and draw nothing
_LABEL_HEIGHT = 0.12  # metres of text
_BOX_ALPHA = 0.45


# --- Colour images ----------------------------------------------------------------------------


def image_to_rgb(message: Image) -> np.ndarray:
    """Return an (H, W, 3) uint8 RGB array from an 8-bit colour Image (rgb8, bgr8, rgba8, bgra8)."""
    if message.encoding not in _TO_RGB_CHANNELS:
        raise InvalidInputError(
            f"colour image encoding '{message.encoding}' cannot be fed to a detector; publish one of "
            f"{', '.join(_TO_RGB_CHANNELS)}"
        )
    pixels = image_to_array(message)
    return np.ascontiguousarray(pixels[:, :, list(_TO_RGB_CHANNELS[message.encoding])])


# --- Detections ---------------------------------------------------------------------------------


def detection_to_message(detection: Detection) -> DetectionMessage:
    message = DetectionMessage(
        class_id=int(detection.class_id), class_name=detection.class_name, score=float(detection.score),
        id=detection.tracker_id,
    )
    message.bbox.center.position.x = float(detection.box.center_x)
    message.bbox.center.position.y = float(detection.box.center_y)
    message.bbox.size.x = float(detection.box.width)
    message.bbox.size.y = float(detection.box.height)
    if detection.mask is not None:
        message.mask = mask_to_message(detection.mask)
    return message


def detection_from_message(message: DetectionMessage) -> Detection:
    """Read one detection; its 3D box, if any, is ignored (3D comes from our own depth)."""
    if not message.class_name:
        raise InvalidInputError(f"detection of class id {message.class_id} has no class_name")
    if not (math.isfinite(message.score) and 0.0 <= message.score <= 1.0):
        raise InvalidInputError(f"detection '{message.class_name}' has score {message.score}, not in [0, 1]")
    box = message.bbox
    values = (box.center.position.x, box.center.position.y, box.size.x, box.size.y, box.center.theta)
    if not all(math.isfinite(value) for value in values):
        raise InvalidInputError(f"detection '{message.class_name}' has a non-finite box {values[:4]}")
    if box.size.x <= 0.0 or box.size.y <= 0.0:
        raise InvalidInputError(
            f"detection '{message.class_name}' has an empty box ({box.size.x} x {box.size.y} pixels)"
        )
    if abs(box.center.theta) > _AXIS_ALIGNED_TOLERANCE:
        raise InvalidInputError(
            f"detection '{message.class_name}' has a rotated box (theta {box.center.theta} rad); "
            "only axis-aligned boxes are supported"
        )
    return Detection(
        class_id=int(message.class_id),
        class_name=message.class_name,
        score=float(message.score),
        box=BoundingBox2D(box.center.position.x, box.center.position.y, box.size.x, box.size.y),
        mask=mask_from_message(message.mask),
        tracker_id=message.id,
    )


def detections_to_message(detections: Sequence[Detection], header: Header) -> DetectionArray:
    """A DetectionArray with ``header``, which must be the header of the image they came from."""
    return DetectionArray(header=header, detections=[detection_to_message(d) for d in detections])


def detections_from_message(message: DetectionArray) -> list[Detection]:
    """Read every detection of an array; the first malformed one raises InvalidInputError."""
    return [detection_from_message(detection) for detection in message.detections]


def mask_to_message(mask: np.ndarray) -> Mask:
    """A boolean (H, W) instance mask as the outline polygon of its largest region.

    The message holds one polygon (yolo_msgs' layout), so holes and extra islands are lost; the
    box already covers the object, and the mask only has to trim background from it.
    """
    import cv2  # only segmenting backends produce masks; keep OpenCV off every other import path

    mask = np.asarray(mask)
    if mask.ndim != 2:
        raise InvalidInputError(f"a mask must be an (H, W) image, got shape {mask.shape}")
    message = Mask(height=int(mask.shape[0]), width=int(mask.shape[1]))
    contours, _ = cv2.findContours(mask.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    if contours:
        outline = max(contours, key=cv2.contourArea).reshape(-1, 2)
        message.data = [Point2D(x=float(x), y=float(y)) for x, y in outline]
    return message


def mask_from_message(message: Mask) -> np.ndarray | None:
    """Rasterise a mask polygon into a boolean (height, width) image; None when there is no mask."""
    if not message.data:
        return None
    if message.height <= 0 or message.width <= 0:
        raise InvalidInputError(f"mask polygon given for an image of {message.width}x{message.height} pixels")
    vertices = np.array([(point.x, point.y) for point in message.data], dtype=np.float64)
    if len(vertices) < 3 or not np.all(np.isfinite(vertices)):
        raise InvalidInputError(f"a mask polygon needs at least 3 finite vertices, got {len(vertices)}")
    import cv2

    raster = np.zeros((message.height, message.width), dtype=np.uint8)
    # Vertices far outside the image are clipped to a margin around it first: they rasterise the
    # same inside it, and a coordinate beyond int32 would otherwise wrap to nonsense in the cast.
    margin = float(max(message.height, message.width))
    vertices[:, 0] = np.clip(vertices[:, 0], -margin, message.width + margin)
    vertices[:, 1] = np.clip(vertices[:, 1], -margin, message.height + margin)
    cv2.fillPoly(raster, [np.round(vertices).astype(np.int32)], 1)
    return raster.astype(bool)


# --- Percepts -----------------------------------------------------------------------------------


def percept_to_message(percept: Percept) -> PerceptMessage:
    """A Percept message; the crop travels as an rgb8 Image (width 0 when the percept has none)."""
    message = PerceptMessage(
        class_name=percept.class_name, class_id=int(percept.class_id), score=float(percept.score),
        tracker_id=percept.tracker_id, stamp=seconds_to_stamp(percept.stamp),
        position=Point(x=float(percept.position[0]), y=float(percept.position[1]), z=float(percept.position[2])),
        size=Vector3(x=float(percept.size[0]), y=float(percept.size[1]), z=float(percept.size[2])),
    )
    message.bbox.center.position.x = float(percept.box.center_x)
    message.bbox.center.position.y = float(percept.box.center_y)
    message.bbox.size.x = float(percept.box.width)
    message.bbox.size.y = float(percept.box.height)
    if percept.crop.size > 0:
        message.crop = array_to_image(percept.crop, "rgb8", Header(stamp=message.stamp))
    if percept.colour is not None:
        message.colour = np.asarray(percept.colour, dtype=np.float32)
    return message


def percept_from_message(message: PerceptMessage, frame_id: str) -> Percept:
    """Read a percept whose position is in ``frame_id`` (the enclosing array's header)."""
    position = np.array([message.position.x, message.position.y, message.position.z], dtype=np.float64)
    size = np.array([message.size.x, message.size.y, message.size.z], dtype=np.float64)
    if not (np.all(np.isfinite(position)) and np.all(np.isfinite(size)) and np.all(size >= 0.0)):
        raise InvalidInputError(
            f"percept '{message.class_name}' has position {position.tolist()} and size {size.tolist()}; "
            "both must be finite and the size non-negative"
        )
    if not (math.isfinite(message.score) and 0.0 <= message.score <= 1.0):
        raise InvalidInputError(f"percept '{message.class_name}' has score {message.score}, not in [0, 1]")
    crop = np.zeros((0, 0, 3), dtype=np.uint8)
    if message.crop.width > 0:
        if message.crop.encoding != "rgb8":
            raise InvalidInputError(f"percept crops must be rgb8, got '{message.crop.encoding}'")
        crop = image_to_array(message.crop)
    colour = _colour_from_message(message)
    box = message.bbox
    return Percept(
        class_name=message.class_name,
        score=float(message.score),
        box=BoundingBox2D(box.center.position.x, box.center.position.y, box.size.x, box.size.y),
        position=position,
        size=size,
        stamp=stamp_to_seconds(message.stamp),
        crop=crop,
        tracker_id=message.tracker_id,
        class_id=int(message.class_id),
        frame_id=frame_id,
        colour=colour,
    )


def _colour_from_message(message: PerceptMessage) -> np.ndarray | None:
    """The percept's colour histogram, None when it has none; a malformed one is refused."""
    colour = np.asarray(message.colour, dtype=np.float32)
    if colour.size == 0:
        return None
    if colour.shape != (COLOUR_BINS,) or not np.all(np.isfinite(colour)) or np.any(colour < 0.0) \
            or abs(float(colour.sum()) - 1.0) > 1e-3:
        raise InvalidInputError(
            f"percept '{message.class_name}' has a colour of {colour.size} values; it must be {COLOUR_BINS} "
            "non-negative values summing to 1 (or none)"
        )
    return colour


def percepts_to_message(percepts: Sequence[Percept], header: Header) -> PerceptArray:
    """A PerceptArray; ``header`` carries the image stamp and the world frame of every percept."""
    mismatched = {percept.frame_id for percept in percepts} - {header.frame_id}
    if mismatched:
        raise InvalidInputError(
            f"percepts in frame(s) {sorted(mismatched)} cannot be published in an array of frame '{header.frame_id}'"
        )
    return PerceptArray(header=header, percepts=[percept_to_message(percept) for percept in percepts])


def percepts_from_message(message: PerceptArray) -> list[Percept]:
    if not message.header.frame_id:
        raise InvalidInputError("a PerceptArray needs header.frame_id, the world frame of its positions")
    return [percept_from_message(percept, message.header.frame_id) for percept in message.percepts]


# --- Camera intrinsics ------------------------------------------------------------------------


def camera_info_to_intrinsics(message: CameraInfo) -> CameraIntrinsics:
    """The pinhole intrinsics of a CameraInfo (its K and image size); distortion is not modelled."""
    if message.width <= 0 or message.height <= 0:
        raise InvalidInputError(f"camera info has no image size ({message.width}x{message.height})")
    return CameraIntrinsics.from_k(list(message.k), int(message.width), int(message.height))


# --- Poses --------------------------------------------------------------------------------------


def pose_from_message(message: PoseMessage) -> Pose:
    """A geometry_msgs/Pose as the transform ``parent <- child`` it describes."""
    position, orientation = message.position, message.orientation
    return Pose.from_quaternion(
        (orientation.x, orientation.y, orientation.z, orientation.w), (position.x, position.y, position.z)
    )


def pose_to_message(pose: Pose) -> PoseMessage:
    x, y, z, w = (float(value) for value in pose.quaternion_xyzw)
    tx, ty, tz = (float(value) for value in pose.translation)
    return PoseMessage(position=Point(x=tx, y=ty, z=tz), orientation=Quaternion(x=x, y=y, z=z, w=w))


def odometry_to_camera_pose(message: Odometry, base_to_camera: Pose) -> Pose:
    """The camera's pose in the odometry's frame: ``world <- base`` composed with ``base <- camera``.

    ``base_to_camera`` is the static pose of the camera's optical frame in the robot's base frame
    (the odometry's child frame), as a URDF would give it.
    """
    return pose_from_message(message.pose.pose).compose(base_to_camera)


def transform_to_pose(message: TransformStamped) -> Pose:
    """A tf2 lookup result (``header.frame_id <- child_frame_id``) as a Pose."""
    translation, rotation = message.transform.translation, message.transform.rotation
    return Pose.from_quaternion(
        (rotation.x, rotation.y, rotation.z, rotation.w), (translation.x, translation.y, translation.z)
    )


# --- Organised point clouds ---------------------------------------------------------------------

_FLOAT_FIELDS = {PointField.FLOAT32: "f4", PointField.FLOAT64: "f8"}


def point_cloud_to_array(message: PointCloud2) -> np.ndarray:
    """Return the (H, W, 3) float32 x, y, z of an organised cloud; NaN points stay NaN.

    Only organised clouds (height > 1, one point per image pixel) can be paired with a detector's
    boxes, so an unorganised cloud is refused rather than guessed at.
    """
    height, width = int(message.height), int(message.width)
    if height <= 1 or width <= 0:
        raise InvalidInputError(
            f"point cloud of {width}x{height} points is not organised; publish the camera's organised "
            "(image-shaped) cloud, registered to the colour image"
        )
    fields = {field.name: field for field in message.fields}
    missing = [name for name in "xyz" if name not in fields]
    if missing:
        raise InvalidInputError(f"point cloud has no field(s) {', '.join(missing)}")
    kinds = {name: _FLOAT_FIELDS.get(fields[name].datatype) for name in "xyz"}
    if None in kinds.values() or any(fields[name].count != 1 for name in "xyz"):
        raise InvalidInputError("point cloud fields x, y, z must each be one FLOAT32 or FLOAT64")
    point_step, row_step = int(message.point_step), int(message.row_step)
    if any(fields[name].offset + np.dtype(kinds[name]).itemsize > point_step for name in "xyz"):
        raise InvalidInputError(f"point cloud fields x, y, z do not fit in a point_step of {point_step} bytes")
    byte_order = ">" if message.is_bigendian else "<"
    dtype = np.dtype({
        "names": list("xyz"),
        "formats": [byte_order + kinds[name] for name in "xyz"],
        "offsets": [int(fields[name].offset) for name in "xyz"],
        "itemsize": point_step,
    })
    if row_step < width * point_step:
        raise InvalidInputError(f"point cloud row_step {row_step} is shorter than {width} points of {point_step} bytes")
    data = message.data
    buffer = np.frombuffer(data.tobytes() if hasattr(data, "tobytes") else bytes(data), dtype=np.uint8)
    if buffer.size < row_step * height:
        raise InvalidInputError(f"point cloud data holds {buffer.size} bytes, {row_step * height} expected")
    rows = np.ascontiguousarray(buffer[: row_step * height].reshape(height, row_step)[:, : width * point_step])
    points = rows.view(dtype).reshape(height, width)
    return np.stack([points[name].astype(np.float32) for name in "xyz"], axis=-1)


def array_to_point_cloud(points: np.ndarray, header: Header | None = None) -> PointCloud2:
    """An organised PointCloud2 (FLOAT32 x, y, z, dense layout) from an (H, W, 3) array."""
    points = np.asarray(points)
    if points.ndim != 3 or points.shape[2] != 3:
        raise InvalidInputError(f"an organised cloud needs an (H, W, 3) array, got shape {points.shape}")
    message = PointCloud2(header=header or Header(), height=int(points.shape[0]), width=int(points.shape[1]))
    message.fields = [PointField(name=name, offset=4 * index, datatype=PointField.FLOAT32, count=1)
                      for index, name in enumerate("xyz")]
    message.is_bigendian = False
    message.point_step = 12
    message.row_step = 12 * message.width
    message.is_dense = bool(np.all(np.isfinite(points)))
    message.data = np.ascontiguousarray(points, dtype="<f4").tobytes()
    return message


# --- RViz markers -------------------------------------------------------------------------------


def percept_markers(percepts: Sequence[Percept], header: Header) -> MarkerArray:
    """One translucent CUBE (the 3D box) and one text label per percept, in ``header.frame_id``.

    The array starts with a DELETEALL, so the boxes of the previous frame vanish even when this
    frame has fewer percepts.
    """
    markers = [Marker(header=header, action=Marker.DELETEALL)]
    for index, percept in enumerate(percepts):
        color = _class_color(percept.class_name)
        extent = np.maximum(np.asarray(percept.size, dtype=np.float64), _MINIMUM_MARKER_EXTENT)
        x, y, z = (float(value) for value in percept.position)
        box = Marker(header=header, ns=BOX_MARKER_NAMESPACE, id=index, type=Marker.CUBE, action=Marker.ADD)
        box.pose.position = Point(x=x, y=y, z=z)
        box.pose.orientation.w = 1.0  # boxes are axis-aligned in the world frame
        box.scale = Vector3(x=float(extent[0]), y=float(extent[1]), z=float(extent[2]))
        box.color = ColorRGBA(r=color[0], g=color[1], b=color[2], a=_BOX_ALPHA)
        label = Marker(
            header=header, ns=LABEL_MARKER_NAMESPACE, id=index, type=Marker.TEXT_VIEW_FACING, action=Marker.ADD,
            text=_label(percept),
        )
        label.pose.position = Point(x=x, y=y, z=z + float(extent[2]) / 2.0 + _LABEL_HEIGHT)
        label.pose.orientation.w = 1.0
        label.scale.z = _LABEL_HEIGHT
        label.color = ColorRGBA(r=color[0], g=color[1], b=color[2], a=1.0)
        markers += [box, label]
    return MarkerArray(markers=markers)


def _label(percept: Percept) -> str:
    identity = f" #{percept.tracker_id}" if percept.tracker_id else ""
    return f"{percept.class_name}{identity} {percept.score:.2f}"


def _class_color(class_name: str) -> tuple[float, float, float]:
    """A saturated colour per class, stable across runs and processes (crc32, not hash())."""
    hue = (zlib.crc32(class_name.encode()) % 360) / 360.0
    red, green, blue = colorsys.hsv_to_rgb(hue, 0.85, 0.95)
    return float(red), float(green), float(blue)
