"""Draw a textured planar quad into colour, depth and instance buffers, with a z-buffer.

A quad is a corner ``origin`` and two edge vectors ``axis_u`` (the texture's rows run along it)
and ``axis_v`` (its columns, top to bottom), in camera coordinates (optical frame). Because a
plane's texture coordinates relate to image pixels by a homography and its inverse depth is an
affine function of the pixel, a whole quad is drawn with one ``cv2.warpPerspective`` over its
bounding rectangle, one affine depth evaluation and one polygon fill; no per-pixel Python. The
quad is clipped against the near plane first, so faces passing beside the camera still draw.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from merlin2_sailor.contract.camera import CameraIntrinsics

#: Camera-frame depth (metres) below which geometry is clipped away.
NEAR_PLANE = 0.05
_SUBPIXEL_BITS = 4  # cv2.fillConvexPoly fixed-point precision


@dataclass(eq=False)
class FrameBuffers:
    """The images being drawn: RGB colour, true depth (metres, inf where empty) and instance ids (-1 none)."""

    color: np.ndarray
    depth: np.ndarray
    instance: np.ndarray


def clip_to_near_plane(points: np.ndarray, near: float = NEAR_PLANE) -> np.ndarray:
    """Sutherland-Hodgman clipping of a convex (N, 3) polygon to z >= near; may return fewer than 3 points."""
    clipped = []
    count = len(points)
    for index in range(count):
        current, following = points[index], points[(index + 1) % count]
        current_in, following_in = current[2] >= near, following[2] >= near
        if current_in:
            clipped.append(current)
        if current_in != following_in:
            fraction = (near - current[2]) / (following[2] - current[2])
            clipped.append(current + fraction * (following - current))
    return np.array(clipped).reshape(-1, 3)


def draw_quad(
    buffers: FrameBuffers,
    intrinsics: CameraIntrinsics,
    origin: np.ndarray,
    axis_u: np.ndarray,
    axis_v: np.ndarray,
    texture: np.ndarray | None,
    instance: int = -1,
    shade: float = 1.0,
    texture_metres: float | None = None,
) -> int:
    """Draw one quad; return the number of pixels it won in the z-buffer.

    ``texture`` spans the whole quad, or, with ``texture_metres`` (the texture's side in metres),
    repeats across it at that scale (floors, furniture). With ``texture`` None only depth and
    instance ids are written, for a caller that colours the pixels itself.
    """
    polygon = clip_to_near_plane(np.array([origin, origin + axis_u, origin + axis_u + axis_v, origin + axis_v]))
    if len(polygon) < 3:
        return 0
    k = intrinsics.k
    pixels = (polygon @ k.T)[:, :2] / polygon[:, 2:3]
    height, width = buffers.depth.shape
    x_min, y_min = max(int(np.floor(pixels[:, 0].min())), 0), max(int(np.floor(pixels[:, 1].min())), 0)
    x_max, y_max = min(int(np.ceil(pixels[:, 0].max())), width - 1), min(int(np.ceil(pixels[:, 1].max())), height - 1)
    if x_max < x_min or y_max < y_min:
        return 0
    rect_width, rect_height = x_max - x_min + 1, y_max - y_min + 1

    mask = np.zeros((rect_height, rect_width), dtype=np.uint8)
    corners = np.round((pixels - (x_min, y_min)) * (1 << _SUBPIXEL_BITS)).astype(np.int64)
    corners = np.clip(corners, -(1 << 28), 1 << 28).astype(np.int32)
    cv2.fillConvexPoly(mask, corners, 1, lineType=cv2.LINE_8, shift=_SUBPIXEL_BITS)

    # Inverse depth is affine in the pixel: 1/z = n . K^-1 [u, v, 1] / (n . origin).
    normal = np.cross(axis_u, axis_v)
    offset = float(normal @ origin)
    if abs(offset) < 1e-12:
        return 0  # seen edge-on
    columns = ((np.arange(x_min, x_max + 1, dtype=np.float32) - intrinsics.cx) / intrinsics.fx) * (normal[0] / offset)
    rows = ((np.arange(y_min, y_max + 1, dtype=np.float32) - intrinsics.cy) / intrinsics.fy) * (normal[1] / offset)
    rows += normal[2] / offset
    with np.errstate(divide="ignore"):
        depth = np.reciprocal(columns[None, :] + rows[:, None])
    region_depth = buffers.depth[y_min:y_max + 1, x_min:x_max + 1]
    wins = mask.view(bool)
    wins &= depth < region_depth
    wins &= depth > 0.0
    won = int(np.count_nonzero(wins))
    if won == 0:
        return 0

    np.copyto(region_depth, depth, where=wins)
    np.copyto(buffers.instance[y_min:y_max + 1, x_min:x_max + 1], np.int16(instance), where=wins)
    if texture is None:
        return won

    # Texture pixel (j, i) -> point origin + s axis_u + t axis_v -> image pixel, shifted to the rectangle.
    texture_height, texture_width = texture.shape[:2]
    if texture_metres is None:
        scale_u, scale_v = 1.0 / texture_width, 1.0 / texture_height
    else:
        scale_u = texture_metres / texture_width / max(float(np.linalg.norm(axis_u)), 1e-9)
        scale_v = texture_metres / texture_height / max(float(np.linalg.norm(axis_v)), 1e-9)
    texture_to_plane = np.array([[scale_u, 0.0, 0.5 * scale_u], [0.0, scale_v, 0.5 * scale_v], [0.0, 0.0, 1.0]])
    plane_to_camera = np.column_stack([axis_u, axis_v, origin])
    shift = np.array([[1.0, 0.0, -x_min], [0.0, 1.0, -y_min], [0.0, 0.0, 1.0]])
    homography = shift @ k @ plane_to_camera @ texture_to_plane
    border = cv2.BORDER_WRAP if texture_metres is not None else cv2.BORDER_REPLICATE
    warped = cv2.warpPerspective(texture, homography, (rect_width, rect_height), flags=cv2.INTER_LINEAR,
                                 borderMode=border)
    if shade != 1.0:
        warped = cv2.convertScaleAbs(warped, alpha=shade)
    np.copyto(buffers.color[y_min:y_max + 1, x_min:x_max + 1], warped, where=wins[:, :, None])
    return won
