"""Real photographs that ship in packages, each with the object class it stands for.

The generated training source textures its objects with crops of real photos so that the
matching network's appearance branch learns from real pixels (lighting, texture, colour
statistics of natural images) rather than from flat synthetic colours. Two sources, both
installable without any download at run time:

- scikit-image's bundled data images (``skimage.data``): astronaut, coffee, chelsea, rocket,
  the stereo motorcycle pair, the Hubble deep field, an immunohistochemistry slide;
- Debian's darknet package photos (folder in ``SAILOR_DARKNET_DATA``, default
  ``/usr/share/darknet/data``; ``scripts/fetch_test_data.sh`` unpacks them without installing):
  dog, person, horses, eagle, giraffe, kite, scream.

The class of a photo is what it mostly shows; instances of a class are different regions of
its photos, so two instances of one class share colour statistics and often overlap, which is
what makes same-class look-alikes hard.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType

import numpy as np

from merlin2_sailor.errors import DependencyError

#: Environment variable naming the darknet photo folder, and its default.
DARKNET_ENVIRONMENT_VARIABLE = "SAILOR_DARKNET_DATA"
DEFAULT_DARKNET_FOLDER = "/usr/share/darknet/data"

#: darknet file stem -> class.
DARKNET_PHOTOS = MappingProxyType(
    {
        "dog": "dog",
        "person": "person",
        "horses": "horse",
        "eagle": "bird",
        "giraffe": "giraffe",
        "kite": "kite",
        "scream": "picture",
    }
)

#: skimage.data function (and, for tuples, the item) -> class.
SKIMAGE_PHOTOS = MappingProxyType(
    {
        "astronaut": "person",
        "coffee": "cup",
        "chelsea": "cat",
        "rocket": "rocket",
        "stereo_motorcycle:0": "motorcycle",
        "stereo_motorcycle:1": "motorcycle",
        "hubble_deep_field": "picture",
        "immunohistochemistry": "picture",
    }
)


@dataclass(frozen=True, slots=True, eq=False)
class Photo:
    """One RGB uint8 photo and the class its regions are labelled with."""

    name: str
    class_name: str
    image: np.ndarray  # (H, W, 3) uint8 RGB


class PhotoLibrary:
    """The photos, grouped by class; ``fingerprint`` changes when the set of photos does."""

    def __init__(self, photos: list[Photo]) -> None:
        if not photos:
            raise DependencyError("The photo library is empty; it needs at least one photo.")
        self.photos = tuple(photos)
        by_class: dict[str, list[int]] = {}
        for index, photo in enumerate(self.photos):
            by_class.setdefault(photo.class_name, []).append(index)
        self.class_names = tuple(sorted(by_class))
        self._by_class: Mapping[str, tuple[int, ...]] = {name: tuple(v) for name, v in by_class.items()}
        digest = hashlib.sha256()
        for photo in self.photos:
            digest.update(f"{photo.name}:{photo.class_name}:{photo.image.shape}".encode())
            digest.update(np.ascontiguousarray(photo.image[::17, ::17]).tobytes())
        self.fingerprint = digest.hexdigest()[:12]

    def photos_of(self, class_name: str) -> tuple[int, ...]:
        return self._by_class[class_name]

    @classmethod
    def load(cls, darknet_folder: str | None = None, use_darknet: bool = True) -> PhotoLibrary:
        """scikit-image's photos plus, when ``use_darknet``, darknet's (see the module docstring)."""
        photos = [_skimage_photo(key, class_name) for key, class_name in SKIMAGE_PHOTOS.items()]
        if use_darknet:
            folder = Path(darknet_folder or os.environ.get(DARKNET_ENVIRONMENT_VARIABLE) or DEFAULT_DARKNET_FOLDER)
            photos += [_darknet_photo(folder, stem, class_name) for stem, class_name in DARKNET_PHOTOS.items()]
        return cls(photos)


def _skimage_photo(key: str, class_name: str) -> Photo:
    try:
        import skimage.data
    except ImportError as error:
        raise DependencyError(
            f"The generated training source needs scikit-image (`pip install scikit-image`): {error}"
        ) from error
    function_name, _, item = key.partition(":")
    loader: Callable[[], object] = getattr(skimage.data, function_name)
    image = loader()
    if item:
        image = image[int(item)]  # type: ignore[index]
    image = np.asarray(image)[..., :3]
    return Photo(name=f"skimage/{key}", class_name=class_name, image=np.ascontiguousarray(image, dtype=np.uint8))


def _darknet_photo(folder: Path, stem: str, class_name: str) -> Photo:
    import cv2

    path = folder / f"{stem}.jpg"
    image = cv2.imread(str(path), cv2.IMREAD_COLOR)
    if image is None:
        raise DependencyError(
            f"Darknet photo {path} not found. Run `scripts/fetch_test_data.sh` and export "
            f"{DARKNET_ENVIRONMENT_VARIABLE} to the folder it prints, install Debian's darknet package, "
            "or generate with use_darknet=False (scikit-image photos only)."
        )
    return Photo(name=f"darknet/{stem}", class_name=class_name, image=np.ascontiguousarray(image[..., ::-1]))
