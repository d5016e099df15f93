"""Reusing the embedding of a crop embedded a moment ago, when the new crop shows the same pixels.

Why: the anchoring node embeds the crop of every percept it has to score. A detection without a
tracker id (ByteTrack starts no track for a detection under its new-track threshold, 0.6, above
the detector's 0.5) is scored anew every frame, so its crop is embedded every frame; with a still
camera and a still object that crop is the same view, frame after frame, and its embedding too.
Measured in the pipeline benchmark with the real detector (issue 16): those embeddings were the
anchoring node's cost, 57 % of a core, and the next obstacle to a 15 Hz camera on two cores.

An embedding is a function of its crop alone, so a crop that shows what a recent one showed may
take its embedding: one of the same size (within ``size_slack`` pixels each way) whose 16 x 16
thumbnail differs from the recent one's by at most ``tolerance`` grey levels on average. A camera
sensor's noise stays under that once averaged over a thumbnail's cells; another object, the
same object from elsewhere, or the scene changed around it differ by tens of levels. The reused
embedding is a genuine one of the same view a frame or two earlier: as good a sample of the object
as a fresh one, since the embedder itself moves with a sensor's noise (4 grey levels of noise move
its features by 12-49 % of the median distance between two objects' crops; a test holds the reused
one nearest its own object's fresh embedding). Crops are remembered for ``memory_calls`` calls (a call
is a frame) and at most ``capacity`` of them: no pose, time or identity is involved, only pixels.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import cv2
import numpy as np

from merlin2_sailor.errors import ConfigurationError

THUMBNAIL_SIDE = 16


class Embedder(Protocol):
    def embed(self, crops: Sequence[np.ndarray]) -> np.ndarray: ...


@dataclass(frozen=True, slots=True)
class CropReuseConfig:
    """``tolerance``: grey levels (0-255) of mean thumbnail difference under which a crop is the
    same view as a recent one, 0 to embed every crop; ``size_slack`` (pixels); ``memory_calls``:
    how many calls a crop is remembered for; ``capacity``: the most crops remembered. The
    tolerance's default is the anchoring node's parameter's (``MatcherSettings.crop_reuse_tolerance``)."""

    tolerance: float
    size_slack: int = 2
    memory_calls: int = 3
    capacity: int = 256

    def __post_init__(self) -> None:
        if not (math.isfinite(self.tolerance) and self.tolerance >= 0.0):
            raise ConfigurationError(f"crop reuse tolerance must be >= 0 grey levels, got {self.tolerance}.")
        if self.size_slack < 0 or self.memory_calls < 1 or self.capacity < 1:
            raise ConfigurationError(
                f"crop reuse needs size_slack >= 0, memory_calls >= 1 and capacity >= 1, got {self.size_slack}, "
                f"{self.memory_calls}, {self.capacity}.")


class ReusingEmbedder:
    """Wraps an embedder; ``reused`` and ``embedded`` count crops (see the module docstring).
    Anything else (``name``, ``threads``, ``config``...) is the wrapped embedder's."""

    def __init__(self, embedder: Embedder, config: CropReuseConfig) -> None:
        self.embedder = embedder
        self.reuse = config
        self.reused = 0
        self.embedded = 0
        self._call = 0
        self._sizes = np.zeros((0, 2), dtype=np.int64)
        self._thumbnails = np.zeros((0, THUMBNAIL_SIDE * THUMBNAIL_SIDE * 3), dtype=np.float32)
        self._features: np.ndarray | None = None
        self._last_used = np.zeros(0, dtype=np.int64)

    def __getattr__(self, name: str) -> Any:
        if name == "embedder":  # not set yet (a copy being made): nothing to forward to
            raise AttributeError(name)
        return getattr(self.embedder, name)

    def embed(self, crops: Sequence[np.ndarray]) -> np.ndarray:
        if self.reuse.tolerance == 0.0 or not crops:
            self.embedded += len(crops)
            return self.embedder.embed(crops)
        self._call += 1
        self._forget_older_than(self._call - self.reuse.memory_calls)
        sizes = np.array([crop.shape[:2] for crop in crops], dtype=np.int64)
        thumbnails = np.stack([thumbnail(crop) for crop in crops])
        sources = np.array([self._recent_view(size, view) for size, view in zip(sizes, thumbnails, strict=True)],
                           dtype=np.int64)
        fresh = np.flatnonzero(sources < 0)
        new_features = (np.asarray(self.embedder.embed([crops[row] for row in fresh]), dtype=np.float32)
                        if fresh.size else None)
        if self._features is None and new_features is not None:
            self._features = np.zeros((0, new_features.shape[1]), dtype=np.float32)
        assert self._features is not None  # every crop was either reused (memory) or embedded just now
        features = np.empty((len(crops), self._features.shape[1]), dtype=np.float32)
        reused = np.flatnonzero(sources >= 0)
        features[reused] = self._features[sources[reused]]
        self._last_used[sources[reused]] = self._call
        if new_features is not None:
            features[fresh] = new_features
            self._remember(sizes[fresh], thumbnails[fresh], new_features)
        self.reused += int(reused.size)
        self.embedded += int(fresh.size)
        return features

    def _recent_view(self, size: np.ndarray, view: np.ndarray) -> int:
        """Index of a remembered crop showing the same view, or -1."""
        if not len(self._sizes):
            return -1
        candidates = np.flatnonzero(np.all(np.abs(self._sizes - size) <= self.reuse.size_slack, axis=1))
        if not candidates.size:
            return -1
        differences = np.abs(self._thumbnails[candidates] - view).mean(axis=1)
        best = int(np.argmin(differences))
        return int(candidates[best]) if differences[best] <= self.reuse.tolerance else -1

    def _remember(self, sizes: np.ndarray, thumbnails: np.ndarray, features: np.ndarray) -> None:
        assert self._features is not None
        capacity = self.reuse.capacity
        self._sizes = np.concatenate([self._sizes, sizes])[-capacity:]
        self._thumbnails = np.concatenate([self._thumbnails, thumbnails])[-capacity:]
        self._features = np.concatenate([self._features, features])[-capacity:]
        self._last_used = np.concatenate([self._last_used, np.full(len(sizes), self._call)])[-capacity:]

    def _forget_older_than(self, call: int) -> None:
        """Drop the crops last shown before ``call``."""
        keep = self._last_used >= call
        if keep.all():
            return
        self._sizes, self._thumbnails = self._sizes[keep], self._thumbnails[keep]
        self._last_used = self._last_used[keep]
        if self._features is not None:
            self._features = self._features[keep]


def thumbnail(crop: np.ndarray) -> np.ndarray:
    """A crop's 16 x 16 area-averaged thumbnail, flattened (float32 grey levels, three channels)."""
    image = np.ascontiguousarray(crop)
    if image.ndim == 2:
        image = np.repeat(image[:, :, np.newaxis], 3, axis=2)
    small = cv2.resize(image[:, :, :3], (THUMBNAIL_SIDE, THUMBNAIL_SIDE), interpolation=cv2.INTER_AREA)
    return small.astype(np.float32).reshape(-1)
