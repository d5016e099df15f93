"""Object textures cut from real photographs, with mipmaps for distant, small objects.

A texture is a region of a photo (``crop``), optionally recoloured (the red mug is the coffee
cup with its pale porcelain turned red), framed by a border (a television's bezel, a book's
cover) or mirrored. When the photo is missing (darknet's photos are an optional download) the
``fallback`` photo is used instead and the substitution is recorded, never silent.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import cv2
import numpy as np

from merlin2_sailor.errors import ConfigurationError, DependencyError
from merlin2_sailor_demos.world.photos import load_photo
from merlin2_sailor_demos.world.yaml_fields import Fields

#: Longest side of a texture's finest level, in pixels; objects rarely cover more on screen.
MAXIMUM_TEXTURE_SIDE = 256
#: Pixels recoloured by ``recolor``: pale (value above) and unsaturated (saturation below), of 255.
RECOLOR_MINIMUM_VALUE = 110
RECOLOR_MAXIMUM_SATURATION = 70


@dataclass(frozen=True, slots=True)
class TextureSpec:
    """How to make one texture from a photo; see the module docstring for each field."""

    photo: str
    fallback: str | None = None
    crop: tuple[int, int, int, int] | None = None  # x_min, y_min, x_max, y_max in photo pixels
    recolor: tuple[int, int, int] | None = None
    border: tuple[int, int, int] | None = None
    border_fraction: float = 0.06
    mirror: bool = False

    @classmethod
    def from_mapping(cls, data: Any, where: str) -> TextureSpec:
        fields = Fields(data, where, ("photo", "fallback", "crop", "recolor", "border", "border_fraction", "mirror"))
        crop = fields.vector("crop", 4, None)
        if crop is not None and not (0 <= crop[0] < crop[2] and 0 <= crop[1] < crop[3]):
            raise fields.fail("crop", "[x_min, y_min, x_max, y_max] with x_min < x_max and y_min < y_max")
        return cls(
            photo=fields.text("photo"),
            fallback=fields.text("fallback", None),
            crop=None if crop is None else tuple(int(value) for value in crop),
            recolor=fields.color("recolor", None),
            border=fields.color("border", None),
            border_fraction=fields.number("border_fraction", 0.06, minimum=0.0, maximum=0.4),
            mirror=fields.boolean("mirror", False),
        )


class Texture:
    """An RGB texture and its mipmap pyramid (each level half the previous one)."""

    def __init__(self, image: np.ndarray) -> None:
        self.levels = [np.ascontiguousarray(image)]
        while min(self.levels[-1].shape[:2]) >= 8:
            self.levels.append(cv2.pyrDown(self.levels[-1]))

    @property
    def image(self) -> np.ndarray:
        return self.levels[0]

    def level_for(self, screen_pixels: float) -> np.ndarray:
        """The finest level no larger than about twice ``screen_pixels`` (the side it covers on screen)."""
        side = max(self.levels[0].shape[:2])
        level = int(math.floor(math.log2(max(side / max(screen_pixels, 1.0), 1.0)))) if screen_pixels > 0 else 0
        return self.levels[min(max(level - 1, 0), len(self.levels) - 1)]


def build_texture_image(spec: TextureSpec, photo: np.ndarray) -> np.ndarray:
    """Apply crop, recolour, border and mirror to ``photo``; the result is at most MAXIMUM_TEXTURE_SIDE."""
    image = photo
    if spec.crop is not None:
        x_min, y_min, x_max, y_max = spec.crop
        image = image[y_min:min(y_max, image.shape[0]), x_min:min(x_max, image.shape[1])]
        if image.size == 0:
            raise ConfigurationError(f"texture crop {spec.crop} is outside photo '{spec.photo}' of {photo.shape[:2]}")
    scale = MAXIMUM_TEXTURE_SIDE / max(image.shape[:2])
    if scale < 1.0:
        image = cv2.resize(image, (max(int(image.shape[1] * scale), 1), max(int(image.shape[0] * scale), 1)),
                           interpolation=cv2.INTER_AREA)
    image = np.array(image, dtype=np.uint8)
    if spec.recolor is not None:
        hsv = cv2.cvtColor(image, cv2.COLOR_RGB2HSV)
        pale = (hsv[:, :, 2] >= RECOLOR_MINIMUM_VALUE) & (hsv[:, :, 1] <= RECOLOR_MAXIMUM_SATURATION)
        brightness = hsv[:, :, 2].astype(np.float32)[:, :, None] / 255.0
        tinted = np.clip(np.asarray(spec.recolor, np.float32) * (0.35 + 0.75 * brightness), 0, 255).astype(np.uint8)
        image[pale] = tinted[pale]
    if spec.border is not None and spec.border_fraction > 0.0:
        thickness = max(int(round(spec.border_fraction * min(image.shape[:2]))), 1)
        image = cv2.copyMakeBorder(image, thickness, thickness, thickness, thickness, cv2.BORDER_CONSTANT,
                                   value=tuple(int(v) for v in spec.border))
    if spec.mirror:
        image = image[:, ::-1]
    return np.ascontiguousarray(image)


class TextureLibrary:
    """The named textures of a world, built from photos on first use and cached."""

    def __init__(self, specs: Mapping[str, TextureSpec], darknet_data: str | None = None) -> None:
        self.specs = dict(specs)
        self._darknet_data = darknet_data
        self._photos: dict[str, np.ndarray] = {}
        self._textures: dict[str, Texture] = {}
        self.substitutions: dict[str, str] = {}
        """Texture name -> the fallback photo used because its own photo was not installed."""

    def __contains__(self, name: str) -> bool:
        return name in self.specs

    def get(self, name: str) -> Texture:
        if name not in self._textures:
            if name not in self.specs:
                raise ConfigurationError(f"no texture named '{name}'; textures: {sorted(self.specs)}")
            spec = self.specs[name]
            try:
                photo = self._photo(spec.photo)
            except DependencyError:
                if spec.fallback is None:
                    raise
                photo = self._photo(spec.fallback)
                self.substitutions[name] = spec.fallback
                spec = TextureSpec(spec.fallback, None, None, spec.recolor, spec.border, spec.border_fraction,
                                   spec.mirror)
            self._textures[name] = Texture(build_texture_image(spec, photo))
        return self._textures[name]

    def _photo(self, name: str) -> np.ndarray:
        if name not in self._photos:
            self._photos[name] = load_photo(name, self._darknet_data)
        return self._photos[name]
