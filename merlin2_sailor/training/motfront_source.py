"""MOTFront (the paper's synthetic indoor set, rendered from 3D-FRONT) as a training source.

Layout read here. MOTFront could not be downloaded to check it; this is the layout its authors'
public loader code reads (BlenderProc output, COCO-style annotations extended with 3D boxes),
found by code search, and it is an **assumption until checked against a real copy**:

    <root>/<split>/<sequence>/coco_data/coco_annotations.json
    <root>/<split>/<sequence>/coco_data/rgb_0000.png, rgb_0001.png, ...   (images[].file_name)
    <root>/<split>/<sequence>/0.hdf5, 1.hdf5, ...                          (depth, campose: not read)
    <root>/3D_front_mapping.csv                                            (optional: id,name,...)

``<split>`` is ``train``, ``val`` or ``test`` (the set's own split, kept); a root holding the
sequence folders directly is split by :func:`~.external_source.assign_splits` instead.
``coco_annotations.json`` holds ``images`` ({id, file_name, width, height}; one per frame, in
frame order by id), ``categories`` ({id, name}; optional) and ``annotations``, one per object and
frame: ``image_id``, ``category_id``, ``id`` (the object's identity across the sequence, as the
authors' tracking metrics use it), ``bbox`` (x, y, w, h pixels) and ``3Dbbox`` (8 corners, world
frame, metres). ``3Dloc`` / ``3Drot`` / ``3Dscale`` / ``segmentation`` / ``jid`` are not needed.

What becomes of it: a sequence is a scene, a frame a sample, an annotation an observation of
instance ``id`` (numbered per scene in order of first sight), class = the category's name
(``categories``, else ``3D_front_mapping.csv``, else ``category_<id>``), position = the 3D box's
centre, size = its axis-aligned extent per world axis (how SAILOR measures a percept's size:
min/max per axis), crop = ``bbox`` cut from the RGB frame (clipped; smaller than
``min_crop_pixels`` -> not an observation). The set has no timestamps: frame ``k`` is stamped
``k * frame_interval`` seconds. Depth images and camera poses (in the ``.hdf5`` files, which
would need h5py) are not read: the boxes are already in the world frame, so no feature needs
them; ``Sample.camera_to_world`` is therefore the identity and ``Observation.depth`` is NaN.

To adapt to a different copy, change :class:`MotFrontConfig` (file names, the identity key)
or :meth:`MotFrontSource._observe`; everything downstream only sees observations.
"""

from __future__ import annotations

import csv
import hashlib
import json
import warnings
from collections import defaultdict
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import ConfigurationError, DependencyError, InvalidInputError
from merlin2_sailor.training.external_source import (
    SPLITS,
    ImageObservation,
    ImageSource,
    assign_splits,
    clip_box,
    file_stamp,
    image_observation,
)
from merlin2_sailor.training.generated_scenes import Sample, Scene

#: Bump when the observations made from given files change (crop ids embed it).
ADAPTER_VERSION = 1

#: Our split names -> MOTFront's split folders.
SPLIT_FOLDERS = {"train": "train", "validation": "val", "test": "test"}

MAPPING_FILE = "3D_front_mapping.csv"


@dataclass(frozen=True, slots=True)
class MotFrontConfig:
    """``root``: the data set folder; ``annotations``: the annotation file, relative to a sequence;
    ``identity_key``: the annotation field naming the object; ``frame_interval``: seconds between
    frames; ``min_crop_pixels``: the smallest crop side kept; ``split_fractions``: used only when
    ``root`` has no split folders."""

    root: str
    annotations: str = "coco_data/coco_annotations.json"
    identity_key: str = "id"
    frame_interval: float = 1.0
    min_crop_pixels: int = 8
    split_fractions: tuple[float, float, float] = (0.8, 0.1, 0.1)

    def __post_init__(self) -> None:
        if not self.frame_interval > 0.0:
            raise ConfigurationError(f"MOTFront frame_interval must be positive seconds, got {self.frame_interval}.")
        if self.min_crop_pixels < 1:
            raise ConfigurationError(f"MOTFront min_crop_pixels must be at least 1, got {self.min_crop_pixels}.")


class MotFrontSource(ImageSource):
    """Sequences of a MOTFront copy (see the module docstring for the layout assumed)."""

    name = "motfront"

    @classmethod
    def from_specification(cls, specification: str) -> MotFrontSource:
        """``ROOT``: the data set folder."""
        return cls(MotFrontConfig(root=specification))

    def __init__(self, config: MotFrontConfig) -> None:
        self.config = config
        self.root = Path(config.root).expanduser()
        if not self.root.is_dir():
            raise DependencyError(f"MOTFront root {self.root} not found. {_EXPECTED}")
        self._folders: dict[str, Path] = {}  # scene name -> sequence folder
        splits: dict[str, list[str]] = defaultdict(list)
        split_folders = {s: self.root / f for s, f in SPLIT_FOLDERS.items() if (self.root / f).is_dir()}
        for split, folder in split_folders.items():
            for sequence in self._sequences(folder):
                name = f"{folder.name}/{sequence.name}"
                self._folders[name] = sequence
                splits[split].append(name)
        if not split_folders:
            for sequence in self._sequences(self.root):
                self._folders[sequence.name] = sequence
            splits.update(assign_splits(list(self._folders), config.split_fractions))
        if not self._folders:
            raise DependencyError(f"MOTFront root {self.root} holds no sequence with {config.annotations}. {_EXPECTED}")
        self._splits = {s: tuple(splits.get(s, ())) for s in SPLITS}
        self._categories = _mapping_file(self.root / MAPPING_FILE)
        stamps = "|".join(file_stamp(folder / config.annotations) for folder in self._folders.values())
        description = f"motfront|v{ADAPTER_VERSION}|{self.root.resolve()}|{sorted(asdict(config).items())}|{stamps}"
        self.fingerprint = hashlib.sha256(description.encode()).hexdigest()[:12]

    def split_scene_names(self) -> Mapping[str, Sequence[str]]:
        return self._splits

    def load_scene(self, name: str, split: str, index: int) -> Scene:
        folder = self._folders[name]
        content = _read_json(folder / self.config.annotations)
        categories = {**self._categories, **{int(c["id"]): str(c["name"]) for c in content.get("categories", [])}}
        by_image: dict[Any, list[dict[str, Any]]] = defaultdict(list)
        for annotation in content.get("annotations", []):
            by_image[annotation["image_id"]].append(annotation)
        instances: dict[Any, int] = {}
        samples = []
        for number, image in enumerate(sorted(content.get("images", []), key=lambda i: i["id"])):
            stamp = number * self.config.frame_interval
            path = folder / Path(self.config.annotations).parent / image["file_name"]
            observations = [
                observation
                for annotation in by_image.get(image["id"], ())
                if (observation := self._observe(annotation, name, image, path, number, stamp, instances, categories))
            ]
            samples.append(Sample(stamp, Pose.identity(), tuple(observations)))
        _warn_if_identities_never_repeat(name, samples, self.config.identity_key)
        return Scene(scene_id=f"motfront/{name}", split=split, index=index, samples=tuple(samples))

    def _observe(self, annotation: dict[str, Any], scene: str, image: dict[str, Any], path: Path, sample: int,
                 stamp: float, instances: dict[Any, int], categories: dict[int, str]) -> ImageObservation | None:
        where = f"annotation {annotation.get('id')} of {scene}"
        try:
            x, y, width, height = (float(v) for v in annotation["bbox"])
            corners = np.asarray(annotation["3Dbbox"], dtype=np.float64)
            identity = annotation[self.config.identity_key]
            category = int(annotation["category_id"])
        except (KeyError, TypeError, ValueError) as error:
            raise InvalidInputError(f"MOTFront {where} lacks bbox, 3Dbbox, category_id or "
                                    f"{self.config.identity_key!r}: {error!r}") from error
        if corners.shape != (8, 3) or not np.all(np.isfinite(corners)):
            raise InvalidInputError(
                f"MOTFront {where}: 3Dbbox must be 8 finite (x, y, z) corners, got {corners.shape}."
            )
        box = clip_box(x, y, x + width, y + height, int(image["width"]), int(image["height"]),
                       self.config.min_crop_pixels)
        if box is None:
            return None
        return image_observation(
            crop_id=f"{self.fingerprint}/{scene}/{image['id']}/{identity}",
            instance=instances.setdefault(identity, len(instances)),
            class_name=categories.get(category, f"category_{category}"),
            sample=sample,
            stamp=stamp,
            position=(corners.min(axis=0) + corners.max(axis=0)) / 2.0,
            size=corners.max(axis=0) - corners.min(axis=0),
            depth=float("nan"),
            image=str(path),
            box=box,
        )

    def _sequences(self, folder: Path) -> list[Path]:
        return sorted(p for p in folder.iterdir() if (p / self.config.annotations).is_file())


_EXPECTED = ("Expected <root>/{train,val,test}/<sequence>/coco_data/coco_annotations.json with the RGB frames "
             "beside it (or <root>/<sequence>/... without split folders); see merlin2_sailor/training/"
             "motfront_source.py for the layout assumed.")


def _read_json(path: Path) -> dict[str, Any]:
    try:
        content = json.loads(path.read_text())
    except (OSError, ValueError) as error:
        raise InvalidInputError(f"MOTFront annotations {path} cannot be read as JSON: {error}") from error
    if not isinstance(content, dict):
        raise InvalidInputError(f"MOTFront annotations {path} must be a COCO-style JSON object.")
    return content


def _mapping_file(path: Path) -> dict[int, str]:
    """Category id -> name from BlenderProc's ``3D_front_mapping.csv`` (rows ``id,name,...``)."""
    if not path.is_file():
        return {}
    names = {}
    with path.open(newline="") as handle:
        for row in csv.reader(handle):
            if len(row) >= 2 and row[0].strip().isdigit():
                names[int(row[0])] = row[1].strip()
    return names


def _warn_if_identities_never_repeat(name: str, samples: list[Sample], key: str) -> None:
    """Several frames but no object seen twice: ``key`` is most likely a per-annotation id, not an identity."""
    observations = [o for s in samples for o in s.observations]
    if len(samples) > 1 and len(observations) > 1 and len({o.instance for o in observations}) == len(observations):
        warnings.warn(f"MOTFront sequence {name}: no object is seen in two frames; if the annotation field "
                      f"{key!r} is not the object's identity in this copy, set MotFrontConfig.identity_key.",
                      stacklevel=3)
