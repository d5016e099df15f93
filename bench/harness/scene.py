"""A synthetic RGB-D frame with N objects in view, and its ground-truth detections.

The pipeline benchmarks feed the real nodes, with or without the detector; without it the frame
only has to look like a camera's to the percept generator; with it the objects show real photos
(Debian darknet's dog, horses, people, ...) for the detector to find. A 640x480 colour image, a
registered 16UC1 depth image in millimetres (what a RealSense publishes) with a few pixels
missing, a back wall, and N textured objects at 1.5-3.5 m laid out on a grid so that none hides
another. Detections are the objects'
true boxes with a pixel of noise per frame, as a detector's boxes wobble. ROS-free.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from harness.script import CannotRun
from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor.training.photo_library import DARKNET_ENVIRONMENT_VARIABLE, DEFAULT_DARKNET_FOLDER

WIDTH, HEIGHT = 640, 480
WALL_MILLIMETRES = 5000
MISSING_DEPTH_FRACTION = 0.02
BOX_NOISE_PIXELS = 1.0
#: The most of its cell a photo object fills (SSD-MobileNet misses most objects under ~80 px).
PHOTO_CELL_FRACTION = 0.9
#: Everyday classes, most of them grounded to their own PDDL type by config/grounding.yaml.
CLASS_NAMES = ("cup", "book", "bottle", "bowl", "teddy bear", "cell phone", "wine glass", "chair", "laptop", "vase")
#: Camera 1 m above the map origin looking along world +x (optical z forward, x right, y down).
CAMERA_TO_WORLD = Pose(np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]]), np.array([0.0, 0.0, 1.0]))


@dataclass(frozen=True)
class SceneObject:
    class_id: int
    class_name: str
    box: BoundingBox2D


@dataclass(frozen=True)
class Scene:
    intrinsics: CameraIntrinsics
    camera_to_world: Pose
    color: np.ndarray  # (H, W, 3) uint8, RGB
    depth_millimetres: np.ndarray  # (H, W) uint16, 0 where there is no measurement
    objects: tuple[SceneObject, ...]


def make_scene(object_count: int, seed: int = 0, width: int = WIDTH, height: int = HEIGHT,
               photos: Sequence[np.ndarray] = ()) -> Scene:
    """``object_count`` objects on a grid filling the image, each 60 % of its cell; with ``photos``
    (RGB images), each object shows one of them, so that a real detector has real objects to find."""
    if object_count < 1:
        raise ValueError("a scene needs at least one object")
    rng = np.random.default_rng(seed)
    columns = math.ceil(math.sqrt(object_count * width / height))
    rows = math.ceil(object_count / columns)
    cell_width, cell_height = width / columns, height / rows
    color = rng.integers(90, 140, (height, width, 3), dtype=np.uint8)
    depth = (WALL_MILLIMETRES + rng.normal(0.0, 5.0, (height, width))).astype(np.uint16)
    objects = []
    for index in range(object_count):
        row, column = divmod(index, columns)
        centre_x = (column + 0.5 + rng.uniform(-0.1, 0.1)) * cell_width
        centre_y = (row + 0.5 + rng.uniform(-0.1, 0.1)) * cell_height
        box = BoundingBox2D(centre_x, centre_y, 0.6 * cell_width, 0.6 * cell_height)
        if photos:  # as large as the cell allows with the photo's own aspect: the detector needs size
            photo_height, photo_width = photos[index % len(photos)].shape[:2]
            scale = PHOTO_CELL_FRACTION * min(cell_width / photo_width, cell_height / photo_height)
            box = BoundingBox2D((column + 0.5) * cell_width, (row + 0.5) * cell_height,
                                photo_width * scale, photo_height * scale)
        x_min, y_min, x_max, y_max = (int(round(v)) for v in box.corners)
        distance = rng.uniform(1500.0, 3500.0)
        depth[y_min:y_max, x_min:x_max] = (distance + rng.normal(0.0, 5.0, (y_max - y_min, x_max - x_min))).astype(
            np.uint16)
        if photos:
            import cv2

            color[y_min:y_max, x_min:x_max] = cv2.resize(photos[index % len(photos)], (x_max - x_min, y_max - y_min),
                                                         interpolation=cv2.INTER_AREA)
        else:
            base = rng.integers(0, 256, 3)
            texture = rng.integers(-40, 40, (y_max - y_min, x_max - x_min, 3))
            color[y_min:y_max, x_min:x_max] = np.clip(base + texture, 0, 255).astype(np.uint8)
        class_id = index % len(CLASS_NAMES)
        objects.append(SceneObject(class_id, CLASS_NAMES[class_id], box))
    depth[rng.random((height, width)) < MISSING_DEPTH_FRACTION] = 0
    focal = 525.0 * width / 640.0
    intrinsics = CameraIntrinsics(fx=focal, fy=focal, cx=(width - 1) / 2.0, cy=(height - 1) / 2.0,
                                  width=width, height=height)
    return Scene(intrinsics, CAMERA_TO_WORLD, color, depth, tuple(objects))


#: Real photos of COCO objects (Debian darknet; scripts/fetch_test_data.sh): what the detector finds.
PHOTO_NAMES = ("dog", "horses", "person", "giraffe", "eagle", "kite")
#: Where scripts/fetch_test_data.sh unpacks them in this checkout, when the system has no darknet package.
CHECKOUT_PHOTOS = Path(__file__).resolve().parents[2] / "build" / "test-data" / "usr" / "share" / "darknet" / "data"


class NoPhotosError(CannotRun):
    """The benchmark needs the darknet photos and none were found."""


def photo_folder() -> Path:
    """The darknet photo folder: ``SAILOR_DARKNET_DATA`` when set, else the system's package, else
    the copy ``scripts/fetch_test_data.sh`` unpacked into this checkout (the one ``make test`` uses),
    so a benchmark run from a fresh clone after ``make setup`` finds what the tests found."""
    if os.environ.get(DARKNET_ENVIRONMENT_VARIABLE):
        return Path(os.environ[DARKNET_ENVIRONMENT_VARIABLE])
    system = Path(DEFAULT_DARKNET_FOLDER)
    if (system / "dog.jpg").is_file() or not (CHECKOUT_PHOTOS / "dog.jpg").is_file():
        return system
    return CHECKOUT_PHOTOS


def require_photos() -> Path:
    """The photo folder, or a clear error saying how to get the photos (without them the detector
    finds nothing in the benchmark's frames and every figure would be empty)."""
    folder = photo_folder()
    if not any((folder / f"{name}.jpg").is_file() for name in PHOTO_NAMES):
        raise NoPhotosError(
            f"no darknet photos in {folder}: the detector benchmark shows real photos for the detector to find. "
            "Run scripts/fetch_test_data.sh (it unpacks them into build/test-data/) or set "
            f"{DARKNET_ENVIRONMENT_VARIABLE} to a folder holding dog.jpg, horses.jpg, person.jpg, ...")
    return folder


def load_object_photos(count: int) -> list[np.ndarray]:
    """Up to ``count`` photos of single objects (RGB): the objects the SSD detector finds with a score
    of 0.7 or more in the darknet photos (:func:`photo_folder`), each cut out with a margin, so
    that each of the scene's objects is one the detector can find again (a whole photo shrunk into
    a scene's cell holds objects too small for it). None where the photos are missing."""
    import cv2

    from merlin2_sailor.perception.detector_registry import create_detector

    folder = photo_folder()
    images = [cv2.imread(str(folder / f"{name}.jpg")) for name in PHOTO_NAMES]
    photos = [cv2.cvtColor(image, cv2.COLOR_BGR2RGB) for image in images if image is not None]
    if not photos:
        return []
    detector = create_detector("ssd_mobilenet", {"score_threshold": 0.7})
    objects = []
    for photo in photos:
        height, width = photo.shape[:2]
        for detection in detector.detect(photo):
            x_min, y_min, x_max, y_max = detection.box.corners
            margin_x, margin_y = 0.1 * (x_max - x_min), 0.1 * (y_max - y_min)
            x0, y0 = int(max(x_min - margin_x, 0)), int(max(y_min - margin_y, 0))
            x1, y1 = int(min(x_max + margin_x, width)), int(min(y_max + margin_y, height))
            if x1 - x0 >= 40 and y1 - y0 >= 40:
                objects.append(photo[y0:y1, x0:x1].copy())
    return objects[:count]


def detections_of(scene: Scene, rng: np.random.Generator, noise: float = BOX_NOISE_PIXELS) -> list[Detection]:
    """The objects' boxes with ``noise`` pixels of jitter, as a detector would report them."""
    detections = []
    for item in scene.objects:
        dx, dy, dw, dh = rng.uniform(-noise, noise, 4)
        box = BoundingBox2D(item.box.center_x + dx, item.box.center_y + dy, item.box.width + dw, item.box.height + dh)
        detections.append(Detection(item.class_id, item.class_name, float(rng.uniform(0.7, 0.95)), box))
    return detections
