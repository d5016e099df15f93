"""nuScenes as a training source, read from its JSON tables (no nuscenes-devkit).

The devkit pins ``numpy<2`` and must never enter the main environment, and the tables are plain
JSON, so this module reads them itself: ``<dataroot>/<version>/{scene, sample, sample_data,
sample_annotation, instance, category, ego_pose, calibrated_sensor, sensor}.json`` and the
images under ``<dataroot>/samples/<CAMERA>/``.

What becomes of them (one nuScenes scene -> one :class:`~.generated_scenes.Scene`):

- a *sample* (a 2 Hz key frame) is a sample, stamped with its timestamp in seconds (nuScenes
  stores microseconds); samples without a key frame of the camera are left out;
- a *sample_annotation* is an observation of its ``instance_token`` (the identity; numbered per
  scene in order of first sight), of class :data:`CLASS_TABLE` [category name], at
  ``translation`` (global frame, metres) with size ``size`` (nuScenes' width, length, height);
- its crop is the box's 8 corners projected into the camera's key-frame image (global -> ego
  with the image's ``ego_pose`` -> camera with ``calibrated_sensor`` -> pixels with its
  ``camera_intrinsic``), the enclosing rectangle clipped to the image. An annotation the camera
  does not see is **not** an observation: a box with a corner behind the camera (less than
  :data:`MIN_DEPTH` in front), one whose visible part is smaller than ``min_crop_pixels``, or
  one whose visibility level (nuScenes' 1..4 = 0-40 %, 40-60 %, 60-80 %, 80-100 % visible) is
  below ``min_visibility``. The matching function pairs what a camera percept holds, and an
  annotation without a crop has no appearance to learn from.

Splits: nuScenes' official train/val split lives in the devkit, not in the tables, so scenes
are split by :func:`~.external_source.assign_splits` (by scene name, 80/10/10 by default).

The tables are loaded whole (as the devkit does): a few GB of memory for v1.0-trainval.
"""

from __future__ import annotations

import hashlib
import json
from collections import defaultdict
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import ConfigurationError, DependencyError, InvalidInputError
from merlin2_sailor.training.external_source import (
    ImageObservation,
    ImageSource,
    assign_splits,
    clip_box,
    file_stamp,
    image_observation,
)
from merlin2_sailor.training.generated_scenes import Sample, Scene

#: Bump when the observations made from given tables change (crop ids embed it).
ADAPTER_VERSION = 1

TABLES = ("scene", "sample", "sample_data", "sample_annotation", "instance", "category", "ego_pose",
          "calibrated_sensor", "sensor")

#: Corners nearer than this to the camera plane (metres) make a box unprojectable.
MIN_DEPTH = 0.1

#: nuScenes category -> the short class a detector would report. The ten detection-challenge
#: classes as the challenge groups them; the rest keep their own name. An unlisted category
#: (a future release) falls back to its last dotted component.
CLASS_TABLE: dict[str, str] = {
    "animal": "animal",
    "human.pedestrian.adult": "pedestrian",
    "human.pedestrian.child": "pedestrian",
    "human.pedestrian.construction_worker": "pedestrian",
    "human.pedestrian.police_officer": "pedestrian",
    "human.pedestrian.personal_mobility": "personal_mobility",
    "human.pedestrian.stroller": "stroller",
    "human.pedestrian.wheelchair": "wheelchair",
    "movable_object.barrier": "barrier",
    "movable_object.debris": "debris",
    "movable_object.pushable_pullable": "pushable_pullable",
    "movable_object.trafficcone": "traffic_cone",
    "static_object.bicycle_rack": "bicycle_rack",
    "vehicle.bicycle": "bicycle",
    "vehicle.bus.bendy": "bus",
    "vehicle.bus.rigid": "bus",
    "vehicle.car": "car",
    "vehicle.construction": "construction_vehicle",
    "vehicle.emergency.ambulance": "ambulance",
    "vehicle.emergency.police": "police_car",
    "vehicle.motorcycle": "motorcycle",
    "vehicle.trailer": "trailer",
    "vehicle.truck": "truck",
}


def short_class(category: str) -> str:
    return CLASS_TABLE.get(category) or category.rsplit(".", 1)[-1]


@dataclass(frozen=True, slots=True)
class NuScenesConfig:
    """``dataroot``: the folder holding ``samples/`` and the version folders; ``version``: e.g.
    ``v1.0-mini`` ("" = the only version folder there); ``camera``: the channel crops come from;
    ``min_visibility``: 1..4 (see the module docstring); ``min_crop_pixels``: the smallest crop
    side kept; ``split_fractions``: train, validation, test shares of the scenes."""

    dataroot: str
    version: str = ""
    camera: str = "CAM_FRONT"
    min_visibility: int = 1
    min_crop_pixels: int = 16
    split_fractions: tuple[float, float, float] = (0.8, 0.1, 0.1)

    def __post_init__(self) -> None:
        if not 1 <= self.min_visibility <= 4:
            raise ConfigurationError(f"nuScenes min_visibility must be 1..4, got {self.min_visibility}.")
        if self.min_crop_pixels < 1:
            raise ConfigurationError(f"nuScenes min_crop_pixels must be at least 1, got {self.min_crop_pixels}.")


@dataclass(frozen=True, slots=True)
class _Camera:
    """One key-frame image: where it is, its size, and the transforms to project into it."""

    image: str
    width: int
    height: int
    intrinsic: np.ndarray  # (3, 3)
    camera_to_world: Pose


class NuScenesSource(ImageSource):
    """Scenes of a nuScenes release (see the module docstring)."""

    name = "nuscenes"

    @classmethod
    def from_specification(cls, specification: str) -> NuScenesSource:
        """``DATAROOT[:VERSION]``: a last part without ``/`` is the version (``/data/nuscenes:v1.0-mini``)."""
        dataroot, version = specification, ""
        head, _, tail = specification.rpartition(":")
        if head and tail and "/" not in tail:
            dataroot, version = head, tail
        return cls(NuScenesConfig(dataroot=dataroot, version=version))

    def __init__(self, config: NuScenesConfig) -> None:
        self.config = config
        self.root = Path(config.dataroot).expanduser()
        self.version = config.version or _only_version(self.root)
        folder = self.root / self.version
        tables = _load_tables(self.root, folder)
        self._index(tables)
        description = (f"nuscenes|v{ADAPTER_VERSION}|{self.root.resolve()}|{self.version}|"
                       f"{sorted(asdict(config).items())}|{file_stamp(folder / 'sample_annotation.json')}")
        self.fingerprint = hashlib.sha256(description.encode()).hexdigest()[:12]
        self._splits = assign_splits(list(self._scenes), config.split_fractions)

    def split_scene_names(self) -> Mapping[str, Sequence[str]]:
        return self._splits

    def load_scene(self, name: str, split: str, index: int) -> Scene:
        samples: list[Sample] = []
        instances: dict[str, int] = {}
        for record in self._samples[self._scenes[name]]:
            camera = self._cameras.get(record["token"])
            if camera is None:
                continue
            stamp = record["timestamp"] * 1e-6
            observations = []
            for annotation in self._annotations.get(record["token"], ()):
                observation = self._observe(annotation, camera, len(samples), stamp, instances)
                if observation is not None:
                    observations.append(observation)
            samples.append(Sample(stamp, camera.camera_to_world, tuple(observations)))
        return Scene(scene_id=f"nuscenes/{name}", split=split, index=index, samples=tuple(samples))

    # --- reading ----------------------------------------------------------------------------

    def _index(self, tables: dict[str, list[dict[str, Any]]]) -> None:
        by_token = {name: {r["token"]: r for r in tables[name]}
                    for name in ("ego_pose", "calibrated_sensor", "sensor", "category", "instance")}
        channels = {r["channel"] for r in tables["sensor"]}
        if self.config.camera not in channels:
            raise ConfigurationError(f"nuScenes {self.version} has no camera {self.config.camera!r}; "
                                     f"its channels are {', '.join(sorted(channels))}.")
        self._scenes = {r["name"]: r["token"] for r in tables["scene"]}
        self._samples: dict[str, list[dict[str, Any]]] = defaultdict(list)
        for record in tables["sample"]:
            self._samples[record["scene_token"]].append(record)
        for records in self._samples.values():
            records.sort(key=lambda r: r["timestamp"])
        self._cameras: dict[str, _Camera] = {}
        for record in tables["sample_data"]:
            if not record.get("is_key_frame"):
                continue
            calibration = _get(by_token, "calibrated_sensor", record["calibrated_sensor_token"])
            if _get(by_token, "sensor", calibration["sensor_token"])["channel"] != self.config.camera:
                continue
            self._cameras[record["sample_token"]] = self._camera(record, calibration, by_token)
        self._annotations: dict[str, list[dict[str, Any]]] = defaultdict(list)
        for record in tables["sample_annotation"]:
            self._annotations[record["sample_token"]].append(record)
        self._classes = {
            token: short_class(_get(by_token, "category", instance["category_token"])["name"])
            for token, instance in by_token["instance"].items()
        }

    def _camera(self, record: dict[str, Any], calibration: dict[str, Any], by_token: dict[str, dict]) -> _Camera:
        ego = _get(by_token, "ego_pose", record["ego_pose_token"])
        intrinsic = np.asarray(calibration.get("camera_intrinsic") or [], dtype=np.float64)
        if intrinsic.shape != (3, 3):
            raise InvalidInputError(f"calibrated_sensor {calibration['token']} of {self.config.camera} has no 3x3 "
                                    f"camera_intrinsic (got shape {intrinsic.shape}).")
        return _Camera(
            image=str(self.root / record["filename"]),
            width=int(record["width"]),
            height=int(record["height"]),
            intrinsic=intrinsic,
            camera_to_world=_pose(ego) @ _pose(calibration),
        )

    def _observe(self, annotation: dict[str, Any], camera: _Camera, sample: int, stamp: float,
                 instances: dict[str, int]) -> ImageObservation | None:
        visibility = str(annotation.get("visibility_token", ""))
        if visibility.isdigit() and int(visibility) < self.config.min_visibility:
            return None
        centre = np.asarray(annotation["translation"], dtype=np.float64)
        size = np.asarray(annotation["size"], dtype=np.float64)
        corners = box_corners(centre, size, annotation["rotation"])
        points = camera.camera_to_world.inverse().transform_points(np.vstack([corners, centre]))
        if np.any(points[:8, 2] < MIN_DEPTH):
            return None
        pixels = points[:8] @ camera.intrinsic.T
        pixels = pixels[:, :2] / pixels[:, 2:3]
        box = clip_box(*pixels.min(axis=0), *pixels.max(axis=0), camera.width, camera.height,
                       self.config.min_crop_pixels)
        if box is None:
            return None
        instance_token = annotation["instance_token"]
        if instance_token not in self._classes:
            raise InvalidInputError(f"sample_annotation {annotation['token']} names instance {instance_token}, "
                                    "which instance.json does not hold.")
        return image_observation(
            crop_id=f"{self.fingerprint}/{annotation['token']}",
            instance=instances.setdefault(instance_token, len(instances)),
            class_name=self._classes[instance_token],
            sample=sample,
            stamp=stamp,
            position=centre,
            size=size,
            depth=float(points[8, 2]),
            image=camera.image,
            box=box,
        )


def box_corners(centre: np.ndarray, size: np.ndarray, rotation_wxyz: Sequence[float]) -> np.ndarray:
    """The (8, 3) corners of a nuScenes box: ``size`` = (width, length, height), length along the
    box's x axis, width along y; ``rotation_wxyz`` turns the box frame into the global frame."""
    width, length, height = size
    signs = np.array([[x, y, z] for x in (1, -1) for y in (1, -1) for z in (1, -1)], dtype=np.float64)
    local = signs * (length / 2, width / 2, height / 2)
    w, x, y, z = rotation_wxyz
    return Pose.from_quaternion((x, y, z, w), centre).transform_points(local)


def _pose(record: dict[str, Any]) -> Pose:
    """``target <- source`` from a nuScenes ``rotation`` (w, x, y, z) and ``translation``."""
    w, x, y, z = record["rotation"]
    return Pose.from_quaternion((x, y, z, w), record["translation"])


def _get(by_token: dict[str, dict], table: str, token: str) -> dict[str, Any]:
    try:
        return by_token[table][token]
    except KeyError:
        raise InvalidInputError(f"nuScenes token {token} is missing from {table}.json; the tables are "
                                "incomplete or from different versions.") from None


def _only_version(root: Path) -> str:
    _require_root(root)
    versions = sorted(p.name for p in root.iterdir() if (p / "scene.json").is_file())
    if len(versions) != 1:
        found = f"found {', '.join(versions)}" if versions else "found none"
        raise ConfigurationError(f"Name the nuScenes version to read (nuscenes:{root}:VERSION): {found} "
                                 f"under {root} (a version folder holds scene.json, sample.json, ...).")
    return versions[0]


def _require_root(root: Path) -> None:
    if not root.is_dir():
        raise DependencyError(
            f"nuScenes dataroot {root} not found. Expected a folder with samples/CAM_FRONT/*.jpg and a "
            "version folder (e.g. v1.0-mini/) holding the JSON tables; download it from nuscenes.org."
        )


def _load_tables(root: Path, folder: Path) -> dict[str, list[dict[str, Any]]]:
    _require_root(root)
    missing = [f"{name}.json" for name in TABLES if not (folder / f"{name}.json").is_file()]
    if missing:
        raise DependencyError(f"nuScenes version folder {folder} lacks {', '.join(missing)}; expected the "
                              f"tables {', '.join(n + '.json' for n in TABLES)} there.")
    tables = {}
    for name in TABLES:
        path = folder / f"{name}.json"
        try:
            tables[name] = json.loads(path.read_text())
        except (OSError, ValueError) as error:
            raise InvalidInputError(f"nuScenes table {path} cannot be read as JSON: {error}") from error
        if not isinstance(tables[name], list):
            raise InvalidInputError(f"nuScenes table {path} must be a JSON list of records.")
    return tables
