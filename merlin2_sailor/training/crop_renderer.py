"""Render one view of an object: a region of a real photo, changed the way a camera changes it.

A detector's crop of the same object differs from view to view: the box is a little off, the
object is nearer or farther (fewer pixels, so blurrier once resized to 224 px), it is seen from
a slightly different angle (a perspective warp), the light changes (gain and bias), the lens
and motion blur it, and the sensor adds noise. :class:`ViewChange` holds one draw of those
changes; :func:`render_crop` applies it to the object's photo region. Both are pure, so a crop
can be rendered again from its parameters whenever the embedding cache misses it.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from merlin2_sailor.errors import ConfigurationError


@dataclass(frozen=True, slots=True)
class Region:
    """A rectangle of a photo in pixels: the object instance's appearance."""

    photo: int  # index in the PhotoLibrary
    x: float
    y: float
    width: float
    height: float


@dataclass(frozen=True, slots=True)
class ViewChangeLimits:
    """The largest change of each kind one view may show (drawn uniformly up to these)."""

    box_jitter: float = 0.06  # fraction of the region's size the detector's box is off by
    warp: float = 0.06  # fraction of the region's size each corner moves (viewpoint)
    rotation_degrees: float = 8.0
    gain: float = 0.3  # brightness gain in [1 - gain, 1 + gain]
    bias: float = 20.0  # brightness offset in grey levels
    blur_sigma: float = 1.2  # pixels, at the crop's resolution
    noise_sigma: float = 6.0  # grey levels

    def __post_init__(self) -> None:
        for name in ("box_jitter", "warp", "rotation_degrees", "gain", "bias", "blur_sigma", "noise_sigma"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0.0):
                raise ConfigurationError(f"view change limit {name} must be a non-negative number, got {value}.")
        if self.gain >= 1.0 or self.box_jitter >= 0.5 or self.warp >= 0.5:
            raise ConfigurationError("view change gain must be below 1, box_jitter and warp below 0.5.")


@dataclass(frozen=True, slots=True)
class ViewChange:
    """One view's changes; ``corners`` are the 4 (x, y) offsets as fractions of the region size."""

    corners: tuple[float, ...]  # 8 values
    rotation_degrees: float
    gain: float
    bias: float
    blur_sigma: float
    noise_sigma: float
    noise_seed: int
    pixels: tuple[int, int]  # (width, height) of the crop as the camera sees it

    @classmethod
    def draw(cls, rng: np.random.Generator, limits: ViewChangeLimits, pixels: tuple[int, int]) -> ViewChange:
        shift = rng.uniform(-limits.box_jitter, limits.box_jitter, size=2)
        corners = rng.uniform(-limits.warp, limits.warp, size=8) + np.tile(shift, 4)
        return cls(
            corners=tuple(float(v) for v in corners),
            rotation_degrees=float(rng.uniform(-limits.rotation_degrees, limits.rotation_degrees)),
            gain=float(rng.uniform(1.0 - limits.gain, 1.0 + limits.gain)),
            bias=float(rng.uniform(-limits.bias, limits.bias)),
            blur_sigma=float(rng.uniform(0.0, limits.blur_sigma)),
            noise_sigma=float(rng.uniform(0.0, limits.noise_sigma)),
            noise_seed=int(rng.integers(0, 2**31 - 1)),
            pixels=(int(pixels[0]), int(pixels[1])),
        )


def render_crop(photo: np.ndarray, region: Region, view: ViewChange) -> np.ndarray:
    """The (h, w, 3) uint8 RGB crop of ``region`` of ``photo`` as ``view`` changes it."""
    width, height = max(view.pixels[0], 8), max(view.pixels[1], 8)
    offsets = np.asarray(view.corners, dtype=np.float64).reshape(4, 2) * (region.width, region.height)
    corners = np.array(
        [
            [region.x, region.y],
            [region.x + region.width, region.y],
            [region.x + region.width, region.y + region.height],
            [region.x, region.y + region.height],
        ]
    )
    centre = corners.mean(axis=0)
    angle = np.deg2rad(view.rotation_degrees)
    rotation = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    source = (corners - centre) @ rotation.T + centre + offsets
    # Render at twice the size, then shrink with area averaging: no aliasing from the warp.
    target = np.array([[0, 0], [2 * width, 0], [2 * width, 2 * height], [0, 2 * height]], dtype=np.float32)
    transform = cv2.getPerspectiveTransform(source.astype(np.float32), target)
    large = cv2.warpPerspective(photo, transform, (2 * width, 2 * height), flags=cv2.INTER_LINEAR,
                                borderMode=cv2.BORDER_REFLECT)
    crop = cv2.resize(large, (width, height), interpolation=cv2.INTER_AREA).astype(np.float32)
    if view.blur_sigma > 0.05:
        crop = cv2.GaussianBlur(crop, (0, 0), view.blur_sigma)
    crop = crop * view.gain + view.bias
    if view.noise_sigma > 0.0:
        crop += np.random.default_rng(view.noise_seed).normal(0.0, view.noise_sigma, size=crop.shape)
    return np.clip(crop, 0.0, 255.0).astype(np.uint8)
