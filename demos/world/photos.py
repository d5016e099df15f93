"""Real photographs that ship in packages, by name: ``skimage/<data function>`` or ``darknet/<stem>``.

The same two sources as :mod:`merlin2_sailor.training.photo_library`: scikit-image's bundled data
images, and the photos of Debian's darknet package in ``$SAILOR_DARKNET_DATA`` (default
``/usr/share/darknet/data``; ``scripts/fetch_test_data.sh`` unpacks them and prints the folder).
Any skimage.data image that ships inside the wheel can be named, not only the library's.
"""

from __future__ import annotations

import os
from pathlib import Path

import cv2
import numpy as np

from merlin2_sailor.errors import ConfigurationError, DependencyError
from merlin2_sailor.training.photo_library import DARKNET_ENVIRONMENT_VARIABLE, DEFAULT_DARKNET_FOLDER

SOURCES = ("skimage", "darknet")


def darknet_folder(folder: str | None = None) -> Path:
    return Path(folder or os.environ.get(DARKNET_ENVIRONMENT_VARIABLE) or DEFAULT_DARKNET_FOLDER)


def load_photo(name: str, darknet_data: str | None = None) -> np.ndarray:
    """The named photo as an (H, W, 3) uint8 RGB array; DependencyError when it is not installed."""
    source, _, item = name.partition("/")
    if source not in SOURCES or not item:
        raise ConfigurationError(f"photo '{name}' must be named 'skimage/<name>' or 'darknet/<name>'")
    if source == "skimage":
        return _skimage_photo(item)
    return _darknet_photo(darknet_folder(darknet_data) / f"{item}.jpg")


def _skimage_photo(item: str) -> np.ndarray:
    try:
        import skimage.data
    except ImportError as error:
        raise DependencyError(f"photo skimage/{item} needs scikit-image (pip install scikit-image)") from error
    loader = getattr(skimage.data, item, None)
    if loader is None or not callable(loader):
        raise ConfigurationError(f"skimage.data has no image '{item}'")
    try:
        image = np.asarray(loader())
    except Exception as error:  # images outside the wheel need a download (pooch), unavailable offline
        raise DependencyError(f"skimage.data.{item} is not bundled with scikit-image here: {error}") from error
    if image.ndim == 2:
        image = np.repeat(image[:, :, None], 3, axis=2)
    if image.dtype != np.uint8:
        image = (255.0 * image / max(float(image.max()), 1e-9)).astype(np.uint8)
    return np.ascontiguousarray(image[:, :, :3])


def _darknet_photo(path: Path) -> np.ndarray:
    image = cv2.imread(str(path), cv2.IMREAD_COLOR)
    if image is None:
        raise DependencyError(
            f"darknet photo {path} not found; run scripts/fetch_test_data.sh and export {DARKNET_ENVIRONMENT_VARIABLE} "
            "to the folder it prints, or give the texture a skimage fallback"
        )
    return np.ascontiguousarray(image[:, :, ::-1])
