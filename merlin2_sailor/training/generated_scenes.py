"""A generated source of percepts with ground-truth identities, for training and evaluation.

nuScenes and MOTFront, the paper's data, cannot be downloaded here, so the project makes its own
scenes. Each scene is a room with many objects, several of one class (look-alikes), some of them
twins cut from the same photo region; a moving RGB-D camera circles through it and observes the
objects inside its frustum over a sequence of samples; now and then an object is moved between
samples (its identity stays).

What is generated is percepts, not full frames: for each visible object a measured world position
(noise growing with depth, as an RGB-D centroid's does), a measured size, a stamp, and the crop a
detector would hand over, rendered from the object's region of a real photo with that view's
changes (:mod:`.crop_renderer`). Rendering whole images and running a detector would add cost
and a detector's errors, but no identity information the matching function can use.

Everything is a pure function of ``(seed, split, index)``: a scene is generated again, bit for
bit, from its id, and a crop from its observation, so neither needs to be stored. Splits are
named; scenes of different splits come from different seeds and are never the same scene.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Iterator
from dataclasses import asdict, dataclass, field

import numpy as np

from merlin2_sailor.contract.camera import CameraIntrinsics, FrustumLimits, points_in_frustum
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.training.crop_renderer import Region, ViewChange, ViewChangeLimits, render_crop
from merlin2_sailor.training.photo_library import PhotoLibrary

#: Bump when the generator's output changes for a given configuration (it invalidates caches).
GENERATOR_VERSION = 1


def _range(name: str, values: tuple[float, float], minimum: float = 0.0) -> None:
    low, high = values
    if not (math.isfinite(low) and math.isfinite(high) and minimum <= low <= high):
        raise ConfigurationError(
            f"scene {name} must be a range (low, high) with {minimum} <= low <= high, got {values}."
        )


@dataclass(frozen=True, slots=True)
class SceneConfig:
    """How scenes look. Distances in metres, times in seconds.

    ``classes_per_scene``: classes drawn per scene (objects share them, so most classes have
    several instances); ``cluster_probability``: chance an instance is put next to another of its
    class, ``cluster_distance`` apart (look-alikes side by side, as mugs on a table);
    ``twin_probability``: chance an instance copies the photo region of another of its class
    (only position and time tell them apart); ``move_probability``: chance per object and sample
    that it is moved ``move_distance`` away; ``detection_probability``: chance a visible object
    is detected; ``position_noise`` + ``position_noise_per_metre`` x depth: the standard deviation
    per axis of a measured centroid.
    """

    objects: tuple[int, int] = (10, 16)
    samples: int = 12
    room_size: float = 8.0
    classes_per_scene: int = 5
    cluster_probability: float = 0.5
    cluster_distance: tuple[float, float] = (0.4, 1.0)
    twin_probability: float = 0.3
    move_probability: float = 0.01
    move_distance: tuple[float, float] = (0.8, 2.5)
    sample_interval: tuple[float, float] = (0.5, 4.0)
    camera_radius: tuple[float, float] = (1.5, 3.0)
    camera_step_degrees: tuple[float, float] = (15.0, 50.0)
    detection_probability: float = 0.95
    position_noise: float = 0.02
    position_noise_per_metre: float = 0.01
    size_noise: float = 0.05
    object_size: tuple[float, float] = (0.15, 0.9)
    views: ViewChangeLimits = field(default_factory=ViewChangeLimits)

    def __post_init__(self) -> None:
        _range("objects", self.objects, 1)
        if self.samples < 2:
            raise ConfigurationError(
                f"scene samples must be at least 2 (pairs need an earlier sample), got {self.samples}."
            )
        if not (math.isfinite(self.room_size) and self.room_size > 2.0):
            raise ConfigurationError(f"scene room_size must be more than 2 m, got {self.room_size}.")
        if self.classes_per_scene < 1:
            raise ConfigurationError(f"scene classes_per_scene must be at least 1, got {self.classes_per_scene}.")
        for name in ("cluster_probability", "twin_probability", "move_probability", "detection_probability"):
            value = getattr(self, name)
            if not (0.0 <= value <= 1.0):
                raise ConfigurationError(f"scene {name} must be a probability in [0, 1], got {value}.")
        for name in ("cluster_distance", "move_distance", "sample_interval", "camera_radius",
                     "camera_step_degrees", "object_size"):
            _range(name, getattr(self, name))
        if self.sample_interval[0] <= 0.0 or self.object_size[0] <= 0.0:
            raise ConfigurationError("scene sample_interval and object_size must be positive.")
        if not (self.position_noise >= 0.0 and self.position_noise_per_metre >= 0.0):
            raise ConfigurationError("scene position_noise and position_noise_per_metre must be >= 0.")
        if not (0.0 <= self.size_noise < 0.5):
            raise ConfigurationError(f"scene size_noise must be in [0, 0.5), got {self.size_noise}.")


@dataclass(frozen=True, slots=True)
class GeneratedSourceConfig:
    """``seed``: the master seed; ``use_darknet``: include the darknet photos (else scikit-image's only)."""

    seed: int = 0
    scene: SceneConfig = field(default_factory=SceneConfig)
    use_darknet: bool = True
    darknet_folder: str = ""

    def __post_init__(self) -> None:
        if self.seed < 0:
            raise ConfigurationError(f"generated source seed must be >= 0, got {self.seed}.")


#: The RGB-D camera of every generated scene (a 640 x 480 sensor with ~70 degrees of view).
INTRINSICS = CameraIntrinsics(fx=457.0, fy=457.0, cx=319.5, cy=239.5, width=640, height=480)
FRUSTUM = FrustumLimits(near=0.4, far=6.0, margin=20.0)
CAMERA_HEIGHT = 1.2


@dataclass(frozen=True, slots=True, eq=False)
class Observation:
    """One detected object in one sample: the percept's content plus its ground truth.

    ``instance`` is the ground-truth identity (unique within a scene); ``twin`` says the instance
    shares its photo region with another of its class; ``crop_id`` names the crop everywhere
    (embedding cache, pair records).

    A source that knows more says so in the keyword-only fields: ``partial`` (the view is cut by
    the image's edge or an occluder, as :mod:`merlin2_sailor.anchoring.partial_view` tells), and
    the anchor of this instance as the anchoring layer would hold it once it has fused this
    observation: ``anchor_position``, ``anchor_size`` and ``gallery`` (crop ids of its appearance
    gallery, newest last). When they are None / empty, the anchor is this observation itself,
    as in the paper's Algorithm 3.
    """

    crop_id: str
    instance: int
    class_name: str
    sample: int
    stamp: float
    position: np.ndarray  # (3,) measured, world frame
    size: np.ndarray  # (3,) measured
    depth: float
    twin: bool
    region: Region
    view: ViewChange
    partial: bool = field(default=False, kw_only=True)
    anchor_position: np.ndarray | None = field(default=None, kw_only=True)
    anchor_size: np.ndarray | None = field(default=None, kw_only=True)
    gallery: tuple[str, ...] = field(default=(), kw_only=True)


@dataclass(frozen=True, slots=True, eq=False)
class Sample:
    stamp: float
    camera_to_world: Pose
    observations: tuple[Observation, ...]


@dataclass(frozen=True, slots=True, eq=False)
class Scene:
    scene_id: str
    split: str
    index: int
    samples: tuple[Sample, ...]

    @property
    def observations(self) -> Iterator[Observation]:
        for sample in self.samples:
            yield from sample.observations


@dataclass(slots=True)
class _Object:
    instance: int
    class_name: str
    position: np.ndarray
    size: np.ndarray
    region: Region
    twin: bool = False


class GeneratedSource:
    """Scenes by (split, index), and the crops of their observations (see the module docstring)."""

    def __init__(self, config: GeneratedSourceConfig | None = None, library: PhotoLibrary | None = None) -> None:
        self.config = config or GeneratedSourceConfig()
        self.library = library or PhotoLibrary.load(self.config.darknet_folder or None, self.config.use_darknet)
        description = repr(asdict(self.config)) + self.library.fingerprint + f"v{GENERATOR_VERSION}"
        self.fingerprint = hashlib.sha256(description.encode()).hexdigest()[:12]

    def scenes(self, split: str, count: int, first: int = 0) -> Iterator[Scene]:
        """Scenes ``first`` .. ``first + count - 1`` of ``split``, generated lazily."""
        for index in range(first, first + count):
            yield self.scene(split, index)

    def scene(self, split: str, index: int) -> Scene:
        if not split or "/" in split:
            raise ConfigurationError(f"split name must be non-empty and contain no '/', got {split!r}.")
        rng = np.random.default_rng([self.config.seed, _split_code(split), index])
        objects = self._place_objects(rng)
        samples = self._observe(rng, objects, split, index)
        return Scene(scene_id=f"{split}/{index}", split=split, index=index, samples=samples)

    def render(self, observation: Observation) -> np.ndarray:
        """The crop of an observation, as a detector would hand it over."""
        return render_crop(self.library.photos[observation.region.photo].image, observation.region, observation.view)

    # --- generation -----------------------------------------------------------------------

    def _place_objects(self, rng: np.random.Generator) -> list[_Object]:
        config = self.config.scene
        count = int(rng.integers(config.objects[0], config.objects[1] + 1))
        class_count = min(config.classes_per_scene, len(self.library.class_names))
        classes = rng.choice(self.library.class_names, size=class_count, replace=False)
        objects: list[_Object] = []
        for instance in range(count):
            class_name = str(classes[rng.integers(class_count)])
            relatives = [o for o in objects if o.class_name == class_name]
            size = rng.uniform(*config.object_size, size=3)
            region = self._draw_region(rng, class_name)
            twin = False
            if relatives and rng.random() < config.twin_probability:
                original = relatives[rng.integers(len(relatives))]
                original.twin = twin = True
                size = original.size * rng.uniform(0.97, 1.03, size=3)
                region = _nudge(rng, original.region)
            if relatives and rng.random() < config.cluster_probability:
                neighbour = relatives[rng.integers(len(relatives))]
                angle = rng.uniform(0.0, 2.0 * math.pi)
                offset = rng.uniform(*config.cluster_distance) * np.array([math.cos(angle), math.sin(angle), 0.0])
                position = neighbour.position + offset
                position[2] = neighbour.position[2] - neighbour.size[2] / 2 + size[2] / 2
            else:
                base = rng.choice([0.0, 0.75])  # floor or table
                position = np.array([*rng.uniform(0.3, config.room_size - 0.3, size=2), base + size[2] / 2])
            position[:2] = np.clip(position[:2], 0.3, config.room_size - 0.3)
            objects.append(_Object(instance, class_name, position, size, region, twin))
        return objects

    def _draw_region(self, rng: np.random.Generator, class_name: str) -> Region:
        candidates = self.library.photos_of(class_name)
        photo_index = int(candidates[rng.integers(len(candidates))])
        height, width = self.library.photos[photo_index].image.shape[:2]
        region_width = width * rng.uniform(0.3, 0.65)
        region_height = height * rng.uniform(0.3, 0.65)
        return Region(
            photo=photo_index,
            x=float(rng.uniform(0.0, width - region_width)),
            y=float(rng.uniform(0.0, height - region_height)),
            width=float(region_width),
            height=float(region_height),
        )

    def _observe(self, rng: np.random.Generator, objects: list[_Object], split: str, index: int) -> tuple[Sample, ...]:
        config = self.config.scene
        centre = np.array([config.room_size / 2, config.room_size / 2, CAMERA_HEIGHT])
        radius = rng.uniform(*config.camera_radius)
        angle = rng.uniform(0.0, 2.0 * math.pi)
        direction = rng.choice([-1.0, 1.0])
        stamp = float(rng.uniform(0.0, 100.0))
        samples = []
        for sample in range(config.samples):
            if sample:
                stamp += float(rng.uniform(*config.sample_interval))
                angle += direction * math.radians(rng.uniform(*config.camera_step_degrees))
                if rng.random() < 0.15:
                    direction = -direction
                for obj in objects:
                    if rng.random() < config.move_probability:
                        _move(rng, obj, config)
            camera_position = centre + radius * np.array([math.cos(angle), math.sin(angle), 0.0])
            # Look across the room: at a point beyond the centre, a little off to one side.
            target = centre - 0.5 * (camera_position - centre) + np.append(rng.normal(0.0, 1.0, 2), -0.5)
            pose = _look_at(camera_position, target)
            positions = np.array([obj.position for obj in objects])
            visible = points_in_frustum(INTRINSICS, pose, positions, FRUSTUM)
            depths = pose.inverse().transform_points(positions)[:, 2]
            observations = []
            for obj, seen, depth in zip(objects, visible, depths, strict=True):
                if not seen or rng.random() > config.detection_probability:
                    continue
                observations.append(self._observation(rng, obj, sample, stamp, float(depth), split, index))
            samples.append(Sample(stamp, pose, tuple(observations)))
        return tuple(samples)

    def _observation(
        self, rng: np.random.Generator, obj: _Object, sample: int, stamp: float, depth: float, split: str, index: int
    ) -> Observation:
        config = self.config.scene
        sigma = config.position_noise + config.position_noise_per_metre * depth
        height_pixels = INTRINSICS.fy * obj.size[2] / depth
        aspect = obj.region.width / obj.region.height
        pixels = (int(np.clip(height_pixels * aspect, 12, 320)), int(np.clip(height_pixels, 12, 320)))
        return Observation(
            crop_id=f"{self.fingerprint}/{split}/{index}/{sample}/{obj.instance}",
            instance=obj.instance,
            class_name=obj.class_name,
            sample=sample,
            stamp=stamp,
            position=obj.position + rng.normal(0.0, sigma, size=3),
            size=obj.size * np.clip(1.0 + rng.normal(0.0, config.size_noise, size=3), 0.5, 1.5),
            depth=depth,
            twin=obj.twin,
            region=obj.region,
            view=ViewChange.draw(rng, config.views, pixels),
        )


def _split_code(split: str) -> int:
    return int.from_bytes(hashlib.sha256(split.encode()).digest()[:4], "little")


def _nudge(rng: np.random.Generator, region: Region) -> Region:
    """A twin's region: the same photo region, shifted and scaled by a few percent."""
    scale = rng.uniform(0.97, 1.03)
    return Region(
        photo=region.photo,
        x=region.x + region.width * rng.uniform(-0.02, 0.02),
        y=region.y + region.height * rng.uniform(-0.02, 0.02),
        width=region.width * scale,
        height=region.height * scale,
    )


def _move(rng: np.random.Generator, obj: _Object, config: SceneConfig) -> None:
    angle = rng.uniform(0.0, 2.0 * math.pi)
    distance = rng.uniform(*config.move_distance)
    obj.position = obj.position.copy()
    obj.position[:2] = np.clip(
        obj.position[:2] + distance * np.array([math.cos(angle), math.sin(angle)]), 0.3, config.room_size - 0.3
    )


def _look_at(position: np.ndarray, target: np.ndarray) -> Pose:
    """Camera-to-world pose of an optical frame (z forward, x right, y down) at ``position``."""
    forward = target - position
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    down = np.cross(forward, right)
    return Pose(np.column_stack((right, down, forward)), position)
