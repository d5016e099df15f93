"""Procedural surface textures for what has no photo: floors, furniture, wall paint.

Objects are textured with real photographs (see :mod:`.textures`); the large plain surfaces of a
house are not what a detector or the appearance embedding look at, so they are generated: wooden
planks, floor tiles, carpet, fabric and painted walls, deterministic for a given name.
"""

from __future__ import annotations

import zlib

import cv2
import numpy as np

#: Pixels per metre of the generated textures.
TEXTURE_RESOLUTION = 100


def _rng(name: str) -> np.random.Generator:
    return np.random.default_rng(zlib.crc32(name.encode()))


def _smooth_noise(rng: np.random.Generator, shape: tuple[int, int], cell: int) -> np.ndarray:
    """Value noise in [0, 1]: a coarse random grid upsampled bilinearly."""
    coarse = rng.random((shape[0] // cell + 2, shape[1] // cell + 2)).astype(np.float32)
    return cv2.resize(coarse, (shape[1], shape[0]), interpolation=cv2.INTER_LINEAR)


def _colorize(base: tuple[int, int, int], shade: np.ndarray) -> np.ndarray:
    return np.clip(np.asarray(base, np.float32)[None, None, :] * shade[:, :, None], 0, 255).astype(np.uint8)


def wood(name: str, size: tuple[int, int] = (256, 256), base: tuple[int, int, int] = (170, 120, 75),
         plank_pixels: int = 20) -> np.ndarray:
    """Planks along the texture's x axis with grain and per-plank tone."""
    rng = _rng(name)
    height, width = size
    rows = np.arange(height)[:, None]
    columns = np.arange(width)[None, :]
    plank = rows // plank_pixels
    tone = 0.85 + 0.25 * rng.random(int(plank.max()) + 1)[plank]
    grain = 0.92 + 0.08 * np.sin(columns * 0.35 + 6.0 * _smooth_noise(rng, size, 16) + plank * 1.7)
    seams = np.where(rows % plank_pixels == 0, 0.6, 1.0)
    return _colorize(base, (tone * grain * seams).astype(np.float32))


def tiles(name: str, size: tuple[int, int] = (256, 256), base: tuple[int, int, int] = (215, 210, 200),
          tile_pixels: int = 32) -> np.ndarray:
    rng = _rng(name)
    rows, columns = np.mgrid[0:size[0], 0:size[1]]
    cell = (rows // tile_pixels) * 97 + columns // tile_pixels
    tone = 0.9 + 0.1 * rng.random(int(cell.max()) + 1)[cell]
    grout = np.where((rows % tile_pixels < 2) | (columns % tile_pixels < 2), 0.55, 1.0)
    return _colorize(base, (tone * grout * (0.95 + 0.05 * _smooth_noise(rng, size, 8))).astype(np.float32))


def speckled(name: str, base: tuple[int, int, int], size: tuple[int, int] = (128, 128),
             amount: float = 0.15, cell: int = 4) -> np.ndarray:
    """A matte surface (carpet, fabric, paint, metal) with fine and coarse noise."""
    rng = _rng(name)
    shade = 1.0 - amount / 2.0 + amount * (0.6 * rng.random(size) + 0.4 * _smooth_noise(rng, size, cell))
    return _colorize(base, shade.astype(np.float32))


FLOOR_TEXTURES = {
    "wood": lambda name: wood(f"floor-{name}"),
    "tiles": lambda name: tiles(f"floor-{name}"),
    "carpet": lambda name: speckled(f"floor-{name}", (120, 110, 140), amount=0.25, cell=3),
}

FURNITURE_TEXTURES = {
    "wood": lambda name: wood(name, (128, 128), (165, 115, 70), plank_pixels=128),
    "dark_wood": lambda name: wood(name, (128, 128), (95, 60, 40), plank_pixels=128),
    "fabric": lambda name: speckled(name, (70, 90, 130), amount=0.3, cell=2),
    "white": lambda name: speckled(name, (235, 235, 230), amount=0.06),
    "metal": lambda name: speckled(name, (150, 155, 160), amount=0.1, cell=16),
}
