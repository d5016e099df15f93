"""Appearance features of object crops, from a frozen backbone, in batches.

SAILOR's matching network compares two crops through the L1 distance of their backbone
features, so the features are returned raw (average-pooled activations, not L2-normalised): the
magnitude is part of what the network was trained on, and normalising here would silently
change its inputs. Callers that want a cosine similarity normalise themselves.

Each crop is resized to the backbone's input (224 px square, aspect ratio not kept, as in the
paper) and normalised with the ImageNet mean and standard deviation by the backbone itself
(OpenVINO folds that into its graph). Crops go through the network in batches. On a CPU small
batches pay best: measured on one core (``bench/bench_embedding.py``), batches of 4 cost per crop
about what single crops do, while batches of 16 cost ~40 % more, because their activations no
longer fit in the cache; on an accelerator large batches win. The backbone runs through OpenVINO
by default (an export of the same torch module, several times faster on a CPU; see
:mod:`.openvino_backbone`), or in torch with ``inference.runtime: native``.

Each embedding ends with the crop's descriptor (:mod:`.crop_descriptor`: 186 values, the
histograms of its centre and its surround and a 6 x 6 thumbnail of its layout) unless
``colour_histogram`` is off: pooled ImageNet features keep the shape of an object and blur its
colour and where things are in it, so a red and a green mug of one make, or a picture and its
mirror image, are closer in them than two views of one object. The descriptor costs about 0.2 ms
a crop against the backbone's 3-38 ms (runtime and threads).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import cv2
import numpy as np

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.inference.settings import InferenceSettings
from merlin2_sailor.perception.backbone import Backbone
from merlin2_sailor.perception.backbone_registry import create_backbone
from merlin2_sailor.perception.crop_descriptor import DESCRIPTOR_SIZE, crop_descriptors
from merlin2_sailor.perception.rgb_crop import checked_rgb_crop


@dataclass(frozen=True, slots=True)
class EmbeddingConfig:
    """``backbone``: a name from :data:`~.backbone_registry.BACKBONES`; ``weights_path``: its weights file,
    when it has none bundled; ``batch_size``: crops per forward pass (4 suits a CPU, see above);
    ``colour_histogram``: end each embedding with the crop's colour and layout descriptor; ``inference``:
    the runtime, device and threads the backbone runs with (OpenVINO by default)."""

    backbone: str = "efficientnet_lite0"
    weights_path: str = ""
    batch_size: int = 4
    colour_histogram: bool = True
    inference: InferenceSettings = field(default_factory=InferenceSettings)

    def __post_init__(self) -> None:
        if self.batch_size < 1:
            raise ConfigurationError(f"batch_size must be at least 1, got {self.batch_size}.")


class CropEmbedder:
    """``embed(crops)`` -> (N, D) float32: raw backbone features, then (when configured) the
    crop's colour and layout descriptor, one row per crop."""

    def __init__(self, config: EmbeddingConfig | None = None, backbone: Backbone | None = None,
                 report: Callable[[str], None] | None = None) -> None:
        self.config = config or EmbeddingConfig()
        self.backbone = backbone or create_backbone(
            self.config.backbone, self.config.weights_path, self.config.inference, report)

    @property
    def colour_bins(self) -> int:
        """How many values at the end of each embedding are the crop descriptor (0: none)."""
        return DESCRIPTOR_SIZE if self.config.colour_histogram else 0

    @property
    def threads(self) -> int:
        """Threads the backbone runs with."""
        return self.backbone.threads

    @property
    def feature_dimension(self) -> int:
        return self.backbone.feature_dimension + self.colour_bins

    @property
    def name(self) -> str:
        """Names what the embeddings hold (e.g. ``efficientnet_lite0+colour186``): an embedding
        cache keeps embeddings of different makes apart by it."""
        return self.config.backbone + (f"+colour{self.colour_bins}" if self.colour_bins else "")

    def embed(self, crops: Sequence[np.ndarray]) -> np.ndarray:
        """Embed (H, W, 3) uint8 RGB crops of any size; an empty list gives a (0, D) array."""
        features = np.empty((len(crops), self.feature_dimension), dtype=np.float32)
        backbone_dimension = self.backbone.feature_dimension
        for start in range(0, len(crops), self.config.batch_size):
            batch = self._resized(crops[start : start + self.config.batch_size], start)
            features[start : start + len(batch), :backbone_dimension] = self.backbone.features(batch)
        if self.colour_bins:
            features[:, backbone_dimension:] = crop_descriptors(crops)
        return features

    def _resized(self, crops: Sequence[np.ndarray], first_index: int) -> np.ndarray:
        """Resize and stack crops into an (N, S, S, 3) uint8 batch (the backbone normalises them)."""
        size = self.backbone.input_size
        batch = np.empty((len(crops), size, size, 3), dtype=np.uint8)
        for offset, crop in enumerate(crops):
            crop = checked_rgb_crop(crop, f"Crop {first_index + offset} (to embed)")
            # Area averaging when shrinking avoids aliasing; bilinear when enlarging small crops.
            shrinking = crop.shape[0] * crop.shape[1] > size * size
            interpolation = cv2.INTER_AREA if shrinking else cv2.INTER_LINEAR
            batch[offset] = cv2.resize(crop, (size, size), interpolation=interpolation)
        return batch
