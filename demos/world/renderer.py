"""Render what the level RGB-D camera sees: colour, true depth and which object owns each pixel.

Fast on one CPU core, with NumPy and OpenCV only:

- Walls: one ray per image column. The camera is level, so a column of pixels is a vertical plane
  of the world and meets the nearest wall at one distance; every pixel of the column sees that
  wall between floor and ceiling.
- Floor and ceiling: the depth of a horizontal plane is constant along an image row, and the floor
  texture (one atlas of the whole house, each room with its own material) reaches the image
  through one homography, i.e. one ``cv2.warpPerspective``.
- Furniture and objects: axis-aligned boxes whose camera-facing faces are quads drawn with a
  z-buffer (:mod:`.rasteriser`), after culling boxes outside the field of view or wholly behind
  the walls. Furniture faces carry a tiled material. An object's visible pixels show its photo
  facing the camera, stretched over the box's silhouette (an impostor): a photo of a cup looks
  like a cup from every side, which a box with a photo on each face does not, and the depth and
  the occlusion still come from the box.

The instance image holds, for each pixel, the index of the object drawn there (-1: walls, floor,
furniture), which is what the ground-truth detector uses to tell visible objects from occluded ones.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from merlin2_sailor_demos.world.camera import CameraConfig, optical_pose
from merlin2_sailor_demos.world.geometry import Box, Pose2D
from merlin2_sailor_demos.world.house import House
from merlin2_sailor_demos.world.materials import FLOOR_TEXTURES, FURNITURE_TEXTURES, TEXTURE_RESOLUTION, speckled
from merlin2_sailor_demos.world.objects import WorldObject
from merlin2_sailor_demos.world.rasteriser import NEAR_PLANE, FrameBuffers, draw_quad
from merlin2_sailor_demos.world.textures import TextureLibrary

CEILING_COLOR = (238, 238, 232)
OUTSIDE_COLOR = (60, 60, 60)
SKIRTING_HEIGHT = 0.08  # metres of white skirting board at the foot of every wall
SKIRTING_COLOR = (245, 245, 240)
#: Brightness of walls running along x and along y: a fixed light makes corners readable.
WALL_SHADE_ALONG_X, WALL_SHADE_ALONG_Y = 1.0, 0.86
#: Direction towards the light, for the faces of boxes (ambient + diffuse).
LIGHT_DIRECTION = np.array([0.35, 0.55, 1.0]) / np.linalg.norm([0.35, 0.55, 1.0])
AMBIENT, DIFFUSE = 0.6, 0.4
WALL_TEXTURE_RESOLUTION = 50  # pixels per metre of the wall atlas
_STRIP_PADDING = 2  # atlas columns between two walls' strips, so interpolation never mixes them


@dataclass(frozen=True, eq=False)
class RenderedFrame:
    """One frame: RGB colour (H, W, 3) uint8, true depth (H, W) float32 metres, instance ids (H, W) int16."""

    color: np.ndarray
    depth: np.ndarray
    instance: np.ndarray


@dataclass(frozen=True, eq=False)
class _Face:
    origin: np.ndarray  # world frame: the face's top-left corner seen from outside
    axis_u: np.ndarray  # to the top-right corner
    axis_v: np.ndarray  # to the bottom-left corner
    normal: np.ndarray  # outward
    shade: float


def box_faces(box: Box, camera_height: float) -> list[_Face]:
    """The side faces and the top of a box, plus its bottom when it hangs above the camera."""
    (x0, y0, z0), (x1, y1, z1) = box.minimum, box.maximum
    dx, dy, dz = x1 - x0, y1 - y0, z1 - z0
    down = np.array([0.0, 0.0, -dz])
    faces = [
        (np.array([x1, y0, z1]), np.array([0.0, dy, 0.0]), down, np.array([1.0, 0.0, 0.0])),
        (np.array([x0, y1, z1]), np.array([0.0, -dy, 0.0]), down, np.array([-1.0, 0.0, 0.0])),
        (np.array([x1, y1, z1]), np.array([-dx, 0.0, 0.0]), down, np.array([0.0, 1.0, 0.0])),
        (np.array([x0, y0, z1]), np.array([dx, 0.0, 0.0]), down, np.array([0.0, -1.0, 0.0])),
        (np.array([x0, y1, z1]), np.array([dx, 0.0, 0.0]), np.array([0.0, -dy, 0.0]), np.array([0.0, 0.0, 1.0])),
    ]
    if z0 > camera_height:
        faces.append((np.array([x0, y0, z0]), np.array([dx, 0.0, 0.0]), np.array([0.0, dy, 0.0]),
                      np.array([0.0, 0.0, -1.0])))
    return [_Face(o, u, v, n, AMBIENT + DIFFUSE * max(float(n @ LIGHT_DIRECTION), 0.0)) for o, u, v, n in faces]


class Renderer:
    """Renders the house and a list of objects from the robot's camera; see the module docstring."""

    def __init__(self, house: House, camera: CameraConfig, textures: TextureLibrary) -> None:
        self.house, self.camera, self.textures = house, camera, textures
        self.intrinsics = camera.intrinsics
        self._column_offsets = (np.arange(camera.width) - camera.cx) / camera.fx
        self._row_offsets = ((np.arange(camera.height) - camera.cy) / camera.fy).astype(np.float32)
        height = camera.mount_height
        with np.errstate(divide="ignore"):
            floor = np.where(self._row_offsets > 0, height / self._row_offsets, np.inf)
            ceiling = np.where(self._row_offsets < 0, (house.wall_height - height) / -self._row_offsets, np.inf)
        self._plane_depth = np.minimum(floor, ceiling).astype(np.float32)
        self._first_floor_row = int(np.argmax(self._row_offsets > 0))
        self._walls = house.wall_array()
        self._wall_vectors = self._walls[:, 2:] - self._walls[:, :2]
        self._wall_lengths = np.linalg.norm(self._wall_vectors, axis=1)
        self._wall_atlas, self._wall_atlas_offsets = self._build_wall_atlas()
        self._floor_atlas = self._build_floor_atlas()
        self._furniture = [
            (piece.box, box_faces(piece.box, height), FURNITURE_TEXTURES[piece.material](piece.name))
            for piece in house.furniture
        ]

    # --- set-up --------------------------------------------------------------------------------------

    def _build_wall_atlas(self) -> tuple[np.ndarray, np.ndarray]:
        """Both sides of every wall as strips of one image (row = height above the floor), painted in
        the colour of the room on that side, with plaster texture and a skirting board; and the
        (walls, 2) first column of each strip."""
        resolution = WALL_TEXTURE_RESOLUTION
        rows = int(np.ceil(self.house.wall_height * resolution)) + 1
        widths = [int(np.ceil(length * resolution)) + 1 + _STRIP_PADDING for length in self._wall_lengths]
        offsets = np.zeros((len(widths), 2), dtype=np.float32)
        total = 2 * sum(widths) + 1
        atlas = np.zeros((rows, max(total, 1), 3), dtype=np.uint8)
        plaster = speckled("wall-paint", (255, 255, 255), (rows, max(total, 1)), 0.08)[:, :, :1] / 255.0
        skirting = np.arange(rows) < SKIRTING_HEIGHT * resolution
        column = 0
        for index, (wall, vector, length) in enumerate(zip(self._walls, self._wall_vectors, self._wall_lengths,
                                                          strict=True)):
            middle = (wall[:2] + wall[2:]) / 2.0
            left = np.array([-vector[1], vector[0]]) / max(length, 1e-9)
            shade = WALL_SHADE_ALONG_X if abs(vector[0]) > abs(vector[1]) else WALL_SHADE_ALONG_Y
            for side, sign in enumerate((1.0, -1.0)):
                room = self.house.room_at(*(middle + sign * 0.05 * left))
                paint = np.asarray(room.wall_color if room else OUTSIDE_COLOR, dtype=np.float32) * shade
                strip = slice(column, column + widths[index])
                atlas[:, strip] = np.clip(plaster[:, strip] * paint, 0, 255).astype(np.uint8)
                atlas[skirting, strip] = SKIRTING_COLOR
                offsets[index, side] = column
                column += widths[index]
        return atlas, offsets

    def _build_floor_atlas(self) -> np.ndarray:
        x_min, y_min, x_max, y_max = self.house.bounds
        resolution = TEXTURE_RESOLUTION
        atlas = np.empty((int(np.ceil((y_max - y_min) * resolution)) + 1,
                          int(np.ceil((x_max - x_min) * resolution)) + 1, 3), dtype=np.uint8)
        atlas[:] = OUTSIDE_COLOR
        for room in self.house.rooms:
            tile = FLOOR_TEXTURES[room.floor](room.name)
            rows = slice(int(round((room.y_min - y_min) * resolution)), int(round((room.y_max - y_min) * resolution)))
            columns = slice(int(round((room.x_min - x_min) * resolution)),
                            int(round((room.x_max - x_min) * resolution)))
            target = atlas[rows, columns]
            repeats = (target.shape[0] // tile.shape[0] + 1, target.shape[1] // tile.shape[1] + 1, 1)
            target[:] = np.tile(tile, repeats)[:target.shape[0], :target.shape[1]]
        return atlas

    # --- rendering ------------------------------------------------------------------------------------

    def render(self, robot: Pose2D, objects: Sequence[WorldObject] = ()) -> RenderedFrame:
        """The frame seen from the camera of a robot at ``robot``; carried objects are not drawn."""
        eye = self.camera.eye(robot)
        buffers, wall_depth = self._render_static(eye)
        self._render_boxes(buffers, eye, wall_depth, objects)
        return RenderedFrame(buffers.color, buffers.depth, buffers.instance)

    def wall_depth(self, eye: Pose2D) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per image column: depth of the nearest wall (inf if none), its index, and the hit's position along it."""
        forward = np.array([np.cos(eye.yaw), np.sin(eye.yaw)])
        right = np.array([np.sin(eye.yaw), -np.cos(eye.yaw)])
        directions = forward[None, :] + self._column_offsets[:, None] * right[None, :]  # forward component 1
        if len(self._walls) == 0:
            empty = np.full(len(directions), np.inf)
            return empty, np.zeros(len(directions), dtype=np.int64), np.zeros(len(directions))
        relative = self._walls[:, :2] - (eye.x, eye.y)
        vectors = self._wall_vectors
        with np.errstate(divide="ignore", invalid="ignore"):
            denominator = directions[:, 0:1] * vectors[None, :, 1] - directions[:, 1:2] * vectors[None, :, 0]
            depth = (relative[:, 0] * vectors[:, 1] - relative[:, 1] * vectors[:, 0])[None, :] / denominator
            along = relative[None, :, 0] * directions[:, 1:2] - relative[None, :, 1] * directions[:, 0:1]
            along /= denominator
        hits = (depth > 1e-9) & (along >= 0.0) & (along <= 1.0)
        depth = np.where(hits, depth, np.inf)
        nearest = np.argmin(depth, axis=1)
        columns = np.arange(len(directions))
        return depth[columns, nearest], nearest, along[columns, nearest] * self._wall_lengths[nearest]

    def _render_static(self, eye: Pose2D) -> tuple[FrameBuffers, np.ndarray]:
        camera = self.camera
        height, width = camera.height, camera.width
        wall_depth, wall_index, along = self.wall_depth(eye)
        wall_depth = wall_depth.astype(np.float32)
        depth = np.minimum(wall_depth[None, :], self._plane_depth[:, None])

        color = np.empty((height, width, 3), dtype=np.uint8)
        first_floor = self._first_floor_row
        color[:first_floor] = CEILING_COLOR
        if first_floor < height:
            color[first_floor:] = cv2.warpPerspective(
                self._floor_atlas, self._floor_homography(eye, first_floor), (width, height - first_floor),
                flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=OUTSIDE_COLOR,
            )

        # Walls: each pixel's height on its column's wall picks the row of that wall's strip in the
        # atlas; heights outside the wall (floor, ceiling) fall outside the atlas and stay transparent.
        relative = self._walls[wall_index, :2] - (eye.x, eye.y)
        vectors = self._wall_vectors[wall_index]
        side = ((vectors[:, 1] * relative[:, 0] - vectors[:, 0] * relative[:, 1]) < 0).astype(np.int64)
        hit = np.isfinite(wall_depth)
        atlas_columns = np.where(hit, self._wall_atlas_offsets[wall_index, side] + along * WALL_TEXTURE_RESOLUTION,
                                 -10.0).astype(np.float32)
        map_x = np.repeat(atlas_columns[None, :], height, axis=0)
        map_y = (camera.mount_height - self._row_offsets[:, None] * np.where(hit, wall_depth, 0.0)[None, :])
        map_y *= np.float32(WALL_TEXTURE_RESOLUTION)
        cv2.remap(self._wall_atlas, map_x, map_y, cv2.INTER_LINEAR, dst=color, borderMode=cv2.BORDER_TRANSPARENT)
        instance = np.full((height, width), -1, dtype=np.int16)
        return FrameBuffers(color, depth, instance), wall_depth

    def _floor_homography(self, eye: Pose2D, first_row: int) -> np.ndarray:
        """Floor atlas pixel -> image pixel (rows from ``first_row``)."""
        x_min, y_min = self.house.bounds[:2]
        atlas_to_world = np.array([[1.0 / TEXTURE_RESOLUTION, 0.0, x_min],
                                   [0.0, 1.0 / TEXTURE_RESOLUTION, y_min], [0.0, 0.0, 1.0]])
        cos_yaw, sin_yaw = np.cos(eye.yaw), np.sin(eye.yaw)
        # Floor point (x, y, 0) in the optical frame: right, down (= camera height), forward.
        world_to_camera = np.array([
            [sin_yaw, -cos_yaw, -(sin_yaw * eye.x - cos_yaw * eye.y)],
            [0.0, 0.0, self.camera.mount_height],
            [cos_yaw, sin_yaw, -(cos_yaw * eye.x + sin_yaw * eye.y)],
        ])
        shift = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, -first_row], [0.0, 0.0, 1.0]])
        return shift @ self.intrinsics.k @ world_to_camera @ atlas_to_world

    def _render_boxes(self, buffers: FrameBuffers, eye: Pose2D, wall_depth: np.ndarray,
                      objects: Sequence[WorldObject]) -> None:
        pose = optical_pose(eye, self.camera.mount_height)
        rotation_t, position = pose.rotation.T, pose.translation
        for box, faces, texture in self._furniture:
            if self._box_visible(box, rotation_t, position, wall_depth):
                self._draw_faces(buffers, faces, rotation_t, position, texture, -1,
                                 texture.shape[1] / TEXTURE_RESOLUTION)
        drawn = []
        for index, item in enumerate(objects):
            if item.carried:
                continue
            box = item.box
            if self._box_visible(box, rotation_t, position, wall_depth):
                self._draw_faces(buffers, box_faces(box, self.camera.mount_height), rotation_t, position, None,
                                 index, None)
                drawn.append((index, item, box))
        for index, item, box in drawn:
            self._paint_object(buffers, index, item, box, rotation_t, position)

    def _paint_object(self, buffers: FrameBuffers, index: int, item: WorldObject, box: Box,
                      rotation_t: np.ndarray, position: np.ndarray) -> None:
        """Colour an object's visible pixels with its photo, facing the camera over its silhouette's box."""
        corners = (box.corners() - position) @ rotation_t.T
        if np.any(corners[:, 2] < NEAR_PLANE):
            return  # reaching behind the camera: leave it as the z-buffer drew it (uncoloured pixels stay)
        columns = self.intrinsics.fx * corners[:, 0] / corners[:, 2] + self.intrinsics.cx
        rows = self.intrinsics.fy * corners[:, 1] / corners[:, 2] + self.intrinsics.cy
        left, right, top, bottom = columns.min() - 0.5, columns.max() + 0.5, rows.min() - 0.5, rows.max() + 0.5
        height, width = buffers.depth.shape
        x_min, x_max = max(int(np.floor(left)), 0), min(int(np.ceil(right)), width - 1)
        y_min, y_max = max(int(np.floor(top)), 0), min(int(np.ceil(bottom)), height - 1)
        if x_max < x_min or y_max < y_min:
            return
        mine = buffers.instance[y_min:y_max + 1, x_min:x_max + 1] == index
        if not mine.any():
            return
        texture = self.textures.get(item.texture).level_for(max(right - left, bottom - top))
        scale_x, scale_y = (right - left) / texture.shape[1], (bottom - top) / texture.shape[0]
        # texture pixel centre j -> image edge coordinate left + (j + 0.5) * scale, minus the rectangle's origin
        affine = np.array([[scale_x, 0.0, left + 0.5 * scale_x - 0.5 - x_min],
                           [0.0, scale_y, top + 0.5 * scale_y - 0.5 - y_min]])
        painted = cv2.warpAffine(texture, affine, (x_max - x_min + 1, y_max - y_min + 1), flags=cv2.INTER_LINEAR,
                                 borderMode=cv2.BORDER_REPLICATE)
        np.copyto(buffers.color[y_min:y_max + 1, x_min:x_max + 1], painted, where=mine[:, :, None])

    def _box_visible(self, box: Box, rotation_t: np.ndarray, position: np.ndarray, wall_depth: np.ndarray) -> float:
        """0 when the box is certainly out of view or behind the walls, else its projected width in pixels."""
        corners = (box.corners() - position) @ rotation_t.T
        depth = corners[:, 2]
        if np.all(depth < NEAR_PLANE):
            return 0.0
        if np.any(depth < NEAR_PLANE):
            return float(self.camera.width)  # reaching past the camera: draw it, clipping decides
        columns = self.intrinsics.fx * corners[:, 0] / depth + self.intrinsics.cx
        rows = self.intrinsics.fy * corners[:, 1] / depth + self.intrinsics.cy
        width, height = self.camera.width, self.camera.height
        if columns.max() < -0.5 or columns.min() > width - 0.5 or rows.max() < -0.5 or rows.min() > height - 0.5:
            return 0.0
        first, last = max(int(columns.min()), 0), min(int(np.ceil(columns.max())), width - 1)
        if depth.min() > wall_depth[first:last + 1].max():
            return 0.0
        return float(max(columns.max() - columns.min(), rows.max() - rows.min(), 1.0))

    def _draw_faces(self, buffers: FrameBuffers, faces: list[_Face], rotation_t: np.ndarray, position: np.ndarray,
                    texture: np.ndarray | None, instance: int, texture_metres: float | None) -> None:
        for face in faces:
            if face.normal @ (position - face.origin) <= 0.0:
                continue  # facing away
            draw_quad(buffers, self.intrinsics, rotation_t @ (face.origin - position), rotation_t @ face.axis_u,
                      rotation_t @ face.axis_v, texture, instance, face.shade, texture_metres)
