"""The training source made of tours of generated houses: what the robot's camera really produces.

Each scene is one random house (:mod:`.generated_houses`; splits are seeded by name, so train,
validation and test houses never coincide, and none is the demo's), toured by the robot
(:mod:`.tour`: every room, a look around in each, then back through the house), rendered by the
demo's renderer, detected by its ground-truth detector and measured by the percept generator.
Every percept of a real object (its instance mask names it; false detections are left out: they
have no identity) becomes an :class:`~merlin2_sailor.training.generated_scenes.Observation`
with its crop as the camera cut it (background, partial views, occlusion and all), its measured
position and size, whether it is a partial view (:mod:`merlin2_sailor.anchoring.partial_view`),
and the anchor of its object as the anchoring layer would hold it after fusing it (an
:class:`~merlin2_sailor.anchoring.anchor.Anchor` fed by the same fusion code: whole views move
and resize it, partial ones do not; a gallery of its last views). So the pairs of Algorithm 3
(:mod:`merlin2_sailor.training.pair_dataset`) are the pairs the network scores on the robot.

It answers what :class:`~merlin2_sailor.training.generated_dataset.GeneratedPairSet` asks of a
source: ``scenes``, ``render``, ``fingerprint`` and ``config``. A tour takes seconds to render,
so each scene's observations are written once as JSON under the cache folder (named by the
fingerprint) and read back by later runs; crops are kept for the last scenes rendered only
(the embedding cache asks for them right after their scene is made, see
:meth:`~merlin2_sailor.training.embedding_cache.EmbeddingCache.ensure`) and a crop asked for
later is rendered again with its scene.
"""

from __future__ import annotations

import hashlib
import json
from collections import OrderedDict
from collections.abc import Iterator
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from merlin2_sailor.anchoring.anchor import Anchor
from merlin2_sailor.anchoring.fusion import FusionConfig
from merlin2_sailor.anchoring.partial_view import PartialViewConfig, partial_views, smaller_than_known
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.training.crop_renderer import Region, ViewChange
from merlin2_sailor.training.generated_scenes import Observation, Sample, Scene
from merlin2_sailor_demos.identity.generated_houses import (
    HouseGeneratorConfig,
    available_photos,
    generate_house,
    twins_of,
)
from merlin2_sailor_demos.identity.tour import Tour, TourConfig
from merlin2_sailor_demos.world.world import World
from merlin2_sailor_demos.world.world_file import WorldDescription

#: Bump when a scene's observations change for a given configuration (it renames every crop):
#: a change of the house generator, the tour or the world's renderer. 2: twins and row members
#: no longer overlap their neighbours; moves try 20 spots.
GENERATOR_VERSION = 2

#: The name ``--source`` gives this source.
SOURCE_NAME = "houses"

#: Scenes whose crops are kept in memory for :meth:`HouseSource.render`.
_CROP_SCENES = 2

#: A crop cut with no change: the camera already made it what it is.
_AS_SEEN = dict(corners=(0.0,) * 8, rotation_degrees=0.0, gain=1.0, bias=0.0, blur_sigma=0.0, noise_sigma=0.0,
                noise_seed=0)


@dataclass(frozen=True, slots=True)
class HouseSourceConfig:
    """``seed``: the master seed of every house and tour; ``houses``: how houses look; ``tour``:
    how the robot goes round each (frames per second: fewer than the camera's, since consecutive
    frames teach little); ``fusion``: how the emulated anchors fuse views (the anchoring layer's);
    ``darknet_folder``: where darknet's photos are ("" = ``$SAILOR_DARKNET_DATA``)."""

    seed: int = 0
    houses: HouseGeneratorConfig = field(default_factory=HouseGeneratorConfig)
    tour: TourConfig = field(default_factory=lambda: TourConfig(rate_hz=3.0, track=False))
    fusion: FusionConfig = field(default_factory=FusionConfig)
    darknet_folder: str = ""

    def __post_init__(self) -> None:
        if self.seed < 0:
            raise ConfigurationError(f"house source seed must be >= 0, got {self.seed}.")


class HouseSource:
    """Scenes by (split, index): tours of generated houses (see the module docstring)."""

    def __init__(self, config: HouseSourceConfig | None = None, cache_folder: str | Path | None = None) -> None:
        self.config = config or HouseSourceConfig()
        self.darknet_data = self.config.darknet_folder or None
        self.photos = tuple(available_photos(self.config.houses.use_darknet, self.darknet_data))
        description = f"{asdict(self.config)!r}|{self.photos}|v{GENERATOR_VERSION}"
        self.fingerprint = hashlib.sha256(description.encode()).hexdigest()[:12]
        self.folder = None if cache_folder is None else Path(cache_folder).expanduser() / self.fingerprint
        self._scenes: dict[tuple[str, int], Scene] = {}
        self._crops: OrderedDict[tuple[str, int], dict[str, np.ndarray]] = OrderedDict()

    # --- the source interface ------------------------------------------------------------------

    def scenes(self, split: str, count: int, first: int = 0) -> Iterator[Scene]:
        for index in range(first, first + count):
            yield self.scene(split, index)

    def scene(self, split: str, index: int) -> Scene:
        if not split or "/" in split:
            raise ConfigurationError(f"split name must be non-empty and contain no '/', got {split!r}.")
        key = (split, index)
        if key not in self._scenes:
            scene = self._load(split, index)
            if scene is None:
                scene = self._generate(split, index)
                self._save(scene)
            self._scenes[key] = scene
        return self._scenes[key]

    def render(self, observation: Observation) -> np.ndarray:
        """The crop of an observation as the camera cut it (its scene is rendered again if need be)."""
        split, index = _scene_key(observation.crop_id)
        crops = self._crops.get((split, index))
        if crops is None or observation.crop_id not in crops:
            self._generate(split, index)
            crops = self._crops[(split, index)]
        return crops[observation.crop_id]

    def house(self, split: str, index: int) -> tuple[WorldDescription, int]:
        """The house of scene ``index`` of ``split`` as a world, and the seed its world runs with
        (for a tour evaluation in a held-out house, or to look at it)."""
        rng = np.random.default_rng([self.config.seed, _split_code(split), index])
        mapping = generate_house(rng, self.config.houses, self.photos, self.darknet_data)
        return WorldDescription.from_mapping(mapping, f"house {split}/{index}"), int(rng.integers(2**31))

    # --- generation -----------------------------------------------------------------------------

    def _generate(self, split: str, index: int) -> Scene:
        description, world_seed = self.house(split, index)
        world = World(description, seed=world_seed, segment=True, darknet_data=self.darknet_data)
        instances = {spec.id: number for number, spec in enumerate(description.objects)}
        twins = twins_of(description)
        anchors: dict[str, Anchor] = {}
        galleries: dict[str, tuple[str, ...]] = {}
        crops: dict[str, np.ndarray] = {}
        samples = []
        gallery_size = self.config.fusion.gallery_size
        for number, frame in enumerate(Tour(world, self.config.tour).frames()):
            flags = partial_views(frame.percepts, frame.camera, PartialViewConfig())
            depths = frame.camera.camera_to_world.inverse().transform_points(
                np.array([p.position for p in frame.percepts], dtype=np.float64).reshape(-1, 3))[:, 2]
            observations = []
            for row, (percept, object_id) in enumerate(zip(frame.percepts, frame.object_ids, strict=True)):
                if object_id is None or percept.crop.size == 0:
                    continue
                crop_id = f"{self.fingerprint}/{split}/{index}/{number}/{row}"
                anchor = anchors.get(object_id)
                partial = bool(flags[row]) or (anchor is not None and smaller_than_known(percept, anchor))
                if anchor is None:
                    anchor = anchors[object_id] = Anchor.from_percept(object_id, percept, None, self.config.fusion,
                                                                      partial)
                else:
                    anchor.absorb(percept, None, self.config.fusion, partial)
                galleries[object_id] = (*galleries.get(object_id, ()), crop_id)[-gallery_size:]
                crops[crop_id] = percept.crop
                x_min, y_min, x_max, y_max = percept.box.corners
                observations.append(Observation(
                    crop_id=crop_id, instance=instances[object_id], class_name=percept.class_name, sample=number,
                    stamp=float(frame.stamp), position=np.asarray(percept.position, dtype=np.float64),
                    size=np.asarray(percept.size, dtype=np.float64), depth=float(depths[row]),
                    twin=object_id in twins,
                    region=Region(-1, float(x_min), float(y_min), float(x_max - x_min), float(y_max - y_min)),
                    view=ViewChange(pixels=(int(percept.crop.shape[1]), int(percept.crop.shape[0])), **_AS_SEEN),
                    partial=partial, anchor_position=anchor.position.copy(), anchor_size=anchor.size.copy(),
                    gallery=galleries[object_id],
                ))
            samples.append(Sample(float(frame.stamp), frame.camera.camera_to_world, tuple(observations)))
        self._crops[(split, index)] = crops
        while len(self._crops) > _CROP_SCENES:
            self._crops.popitem(last=False)
        return Scene(scene_id=f"{split}/{index}", split=split, index=index, samples=tuple(samples))

    # --- the scene cache ------------------------------------------------------------------------

    def _path(self, split: str, index: int) -> Path | None:
        return None if self.folder is None else self.folder / f"{split}-{index}.json"

    def _save(self, scene: Scene) -> None:
        path = self._path(scene.split, scene.index)
        if path is None:
            return
        path.parent.mkdir(parents=True, exist_ok=True)
        temporary = path.with_name(f".{path.name}.tmp")
        content = {"scene_id": scene.scene_id, "samples": [_sample_data(sample) for sample in scene.samples]}
        temporary.write_text(json.dumps(content))
        temporary.rename(path)

    def _load(self, split: str, index: int) -> Scene | None:
        path = self._path(split, index)
        if path is None or not path.is_file():
            return None
        try:
            data = json.loads(path.read_text())
            samples = tuple(_sample_from(item) for item in data["samples"])
        except (ValueError, KeyError, TypeError):
            return None  # a damaged cache file: the scene is made again
        return Scene(scene_id=f"{split}/{index}", split=split, index=index, samples=samples)


def _split_code(split: str) -> int:
    return int.from_bytes(hashlib.sha256(split.encode()).digest()[:4], "little")


def _scene_key(crop_id: str) -> tuple[str, int]:
    parts = crop_id.split("/")
    if len(parts) != 5:
        raise ConfigurationError(f"{crop_id!r} is not a crop id of the house source")
    return parts[1], int(parts[2])


def _sample_data(sample: Sample) -> dict[str, Any]:
    return {
        "stamp": sample.stamp,
        "rotation": sample.camera_to_world.rotation.tolist(),
        "translation": sample.camera_to_world.translation.tolist(),
        "observations": [{
            "crop_id": o.crop_id, "instance": o.instance, "class_name": o.class_name, "sample": o.sample,
            "stamp": o.stamp, "position": o.position.tolist(), "size": o.size.tolist(), "depth": o.depth,
            "twin": o.twin, "box": [o.region.x, o.region.y, o.region.width, o.region.height],
            "pixels": list(o.view.pixels), "partial": o.partial,
            "anchor_position": None if o.anchor_position is None else o.anchor_position.tolist(),
            "anchor_size": None if o.anchor_size is None else o.anchor_size.tolist(), "gallery": list(o.gallery),
        } for o in sample.observations],
    }


def _sample_from(data: dict[str, Any]) -> Sample:
    observations = tuple(Observation(
        crop_id=o["crop_id"], instance=int(o["instance"]), class_name=o["class_name"], sample=int(o["sample"]),
        stamp=float(o["stamp"]), position=np.asarray(o["position"], dtype=np.float64),
        size=np.asarray(o["size"], dtype=np.float64), depth=float(o["depth"]), twin=bool(o["twin"]),
        region=Region(-1, *(float(v) for v in o["box"])),
        view=ViewChange(pixels=(int(o["pixels"][0]), int(o["pixels"][1])), **_AS_SEEN),
        partial=bool(o["partial"]),
        anchor_position=None if o["anchor_position"] is None else np.asarray(o["anchor_position"], dtype=np.float64),
        anchor_size=None if o["anchor_size"] is None else np.asarray(o["anchor_size"], dtype=np.float64),
        gallery=tuple(o["gallery"]),
    ) for o in data["observations"])
    pose = Pose(np.asarray(data["rotation"], dtype=np.float64), np.asarray(data["translation"], dtype=np.float64))
    return Sample(float(data["stamp"]), pose, observations)
