"""What the public-dataset sources (nuScenes, MOTFront) share: image crops, scene splits, ``--source``.

A public data set gives what the generated source makes: scenes of samples, each sample the
objects a camera saw, with their ground-truth identity. Its observations are
:class:`~.generated_scenes.Observation` s, so the pair builder (Algorithm 3), the embedding cache,
the trainer and the identity evaluation read them unchanged. :class:`ImageObservation` adds
where the crop comes from, an image file and a pixel box; the generator-only fields say so
plainly: ``region`` is the box with ``photo = -1`` (no photo-library photo), ``view`` changes
nothing (the real camera already did) and only gives the crop's size, ``twin`` is False (unknown).

An :class:`ImageSource` answers the same two calls as the generated source,
``scenes(split, count, first)`` and ``render(observation)``, plus ``split_size(split)`` (a
public set has a finite number of scenes), so :class:`~.generated_dataset.GeneratedPairSet`
and the training and evaluation commands drive either kind. The sources are chosen by name in
:mod:`.source_registry`, the table above them.
"""

from __future__ import annotations

import hashlib
import math
from abc import ABC, abstractmethod
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import cv2
import numpy as np

from merlin2_sailor.errors import ConfigurationError, DependencyError, InvalidInputError
from merlin2_sailor.training.crop_renderer import Region, ViewChange
from merlin2_sailor.training.generated_scenes import Observation, Scene

#: The split names the commands use, plus ``all`` (every scene of the source, in split order).
SPLITS = ("train", "validation", "test")
ALL = "all"

#: A crop is cut from the image as is: no warp, no light change, no blur, no noise.
_NO_CHANGE = dict(corners=(0.0,) * 8, rotation_degrees=0.0, gain=1.0, bias=0.0, blur_sigma=0.0,
                  noise_sigma=0.0, noise_seed=0)


@dataclass(frozen=True, slots=True, eq=False)
class ImageObservation(Observation):
    """An observation whose crop is ``box`` = (x0, y0, x1, y1) pixels (x1, y1 excluded) of ``image``."""

    image: str
    box: tuple[int, int, int, int]


def image_observation(
    *,
    crop_id: str,
    instance: int,
    class_name: str,
    sample: int,
    stamp: float,
    position: np.ndarray,
    size: np.ndarray,
    depth: float,
    image: str,
    box: tuple[int, int, int, int],
) -> ImageObservation:
    """An :class:`ImageObservation` with the generator-only fields filled as the module says."""
    x0, y0, x1, y1 = box
    return ImageObservation(
        crop_id=crop_id,
        instance=instance,
        class_name=class_name,
        sample=sample,
        stamp=float(stamp),
        position=np.asarray(position, dtype=np.float64).reshape(3),
        size=np.asarray(size, dtype=np.float64).reshape(3),
        depth=float(depth),
        twin=False,
        region=Region(photo=-1, x=float(x0), y=float(y0), width=float(x1 - x0), height=float(y1 - y0)),
        view=ViewChange(pixels=(x1 - x0, y1 - y0), **_NO_CHANGE),
        image=image,
        box=box,
    )


def clip_box(
    x0: float, y0: float, x1: float, y1: float, width: int, height: int, min_pixels: int
) -> tuple[int, int, int, int] | None:
    """The integer box covering (x0, y0)-(x1, y1) inside a width x height image, or None when the
    part inside is narrower or lower than ``min_pixels`` (too small for a detector to report)."""
    if not all(math.isfinite(v) for v in (x0, y0, x1, y1)):
        return None
    left, top = max(int(math.floor(x0)), 0), max(int(math.floor(y0)), 0)
    right, bottom = min(int(math.ceil(x1)), width), min(int(math.ceil(y1)), height)
    if right - left < min_pixels or bottom - top < min_pixels:
        return None
    return left, top, right, bottom


def read_crop(observation: ImageObservation) -> np.ndarray:
    """The (h, w, 3) uint8 RGB crop of an image observation."""
    x0, y0, x1, y1 = observation.box
    image = _read_image(observation.image)
    crop = image[y0:y1, x0:x1]
    if crop.shape[0] != y1 - y0 or crop.shape[1] != x1 - x0:
        raise InvalidInputError(
            f"Crop box {observation.box} of {observation.image} falls outside the image "
            f"({image.shape[1]}x{image.shape[0]}); the annotations and the images do not belong together."
        )
    return np.ascontiguousarray(crop)


@lru_cache(maxsize=16)
def _read_image(path: str) -> np.ndarray:
    # Observations of one sample are embedded together, so a few images cached saves re-decoding.
    image = cv2.imread(path, cv2.IMREAD_COLOR)
    if image is None:
        raise DependencyError(f"Image {path} is missing or unreadable; the data set is incomplete.")
    image = cv2.cvtColor(image, cv2.COLOR_BGR2RGB)
    image.setflags(write=False)
    return image


def assign_splits(
    names: Sequence[str], fractions: tuple[float, float, float] = (0.8, 0.1, 0.1)
) -> dict[str, tuple[str, ...]]:
    """Scene names per split, deterministic and independent of listing order.

    Scenes are ranked by a hash of their name (so neighbouring recordings, often from one place,
    are spread over the splits) and cut by ``fractions`` (train, validation, test). Validation
    gets at least one scene when there are two, test one more when there are three: training
    needs a validation split, and a tiny set should still be usable end to end.
    """
    if len(fractions) != 3 or not all(math.isfinite(f) and f >= 0.0 for f in fractions) or sum(fractions) <= 0.0:
        raise ConfigurationError(f"split fractions must be 3 non-negative numbers, got {fractions}.")
    ranked = sorted(set(names), key=lambda n: (hashlib.sha256(n.encode()).hexdigest(), n))
    total = len(ranked)
    share = [f / sum(fractions) for f in fractions]
    validation = max(round(total * share[1]), 1 if total >= 2 and share[1] > 0.0 else 0)
    test = max(round(total * share[2]), 1 if total >= 3 and share[2] > 0.0 else 0)
    test = min(test, total - validation)
    train = total - validation - test
    return {
        SPLITS[0]: tuple(ranked[:train]),
        SPLITS[1]: tuple(ranked[train : train + validation]),
        SPLITS[2]: tuple(ranked[train + validation :]),
    }


class ImageSource(ABC):
    """Scenes of a public data set by split, and their crops (see the module docstring).

    Subclasses set ``name``, ``config`` (a dataclass) and ``fingerprint`` (which names the data
    and the adapter's settings: crop ids embed it, so the embedding cache never serves stale
    rows), and implement :meth:`split_scene_names` and :meth:`load_scene`.
    """

    name: str
    config: object
    fingerprint: str

    @abstractmethod
    def split_scene_names(self) -> Mapping[str, Sequence[str]]:
        """Scene names of each split in :data:`SPLITS` (disjoint)."""

    @classmethod
    def from_specification(cls, specification: str) -> ImageSource:
        """The source a ``--source`` value names, given what follows ``name:`` (see the registry)."""
        raise NotImplementedError(f"{cls.__name__} is not opened from a --source value; construct it")

    @abstractmethod
    def load_scene(self, name: str, split: str, index: int) -> Scene:
        """One scene, read from the data set's files."""

    def scene_names(self, split: str) -> tuple[str, ...]:
        splits = self.split_scene_names()
        if split == ALL:
            return tuple(n for s in SPLITS for n in splits.get(s, ()))
        if split not in SPLITS:
            raise ConfigurationError(f"{self.name} has the splits {', '.join(SPLITS)} and {ALL}; got {split!r}.")
        return tuple(splits.get(split, ()))

    def split_size(self, split: str) -> int:
        return len(self.scene_names(split))

    def scenes(self, split: str, count: int, first: int = 0) -> Iterator[Scene]:
        """Scenes ``first`` .. ``first + count - 1`` of ``split`` (fewer when the split is smaller), lazily."""
        names = self.scene_names(split)
        for index in range(max(first, 0), min(first + count, len(names))):
            yield self.load_scene(names[index], split, index)

    def render(self, observation: Observation) -> np.ndarray:
        if not isinstance(observation, ImageObservation):
            raise InvalidInputError(f"{self.name} can only crop its own observations, got {observation.crop_id}.")
        return read_crop(observation)


def file_stamp(path: Path) -> str:
    """Size and modification time of a file, for fingerprints (a changed table changes crop ids)."""
    status = path.stat()
    return f"{path.name}:{status.st_size}:{status.st_mtime_ns}"
