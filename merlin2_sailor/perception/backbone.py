"""The port of frozen image backbones for crop embedding.

A backbone turns a batch of normalised 224 px crops into one feature vector per crop. It is
frozen: SAILOR's matching network trains on top of it, never through it. Batches go in and out as
NumPy arrays, so the embedder is the same whichever runtime computes the features: torch, imported
by the torch backbone modules themselves (a deployment without torch stays light), or an exported
model run by :mod:`.openvino_backbone`. Both are chosen in :mod:`.backbone_registry`.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import torch

#: ImageNet channel statistics (RGB, on 0..1 pixels), the normalisation both backbones were trained with.
IMAGENET_MEAN = (0.485, 0.456, 0.406)
IMAGENET_STD = (0.229, 0.224, 0.225)


class Backbone(ABC):
    """A frozen feature extractor: (N, 3, S, S) normalised float32 -> (N, feature_dimension)."""

    feature_dimension: int
    input_size: int = 224
    mean: tuple[float, float, float] = IMAGENET_MEAN
    std: tuple[float, float, float] = IMAGENET_STD

    @property
    def threads(self) -> int:
        """Threads the features are computed with (0 when the runtime does not say)."""
        return 0

    @abstractmethod
    def features(self, batch: np.ndarray) -> np.ndarray:
        """Return the (N, feature_dimension) float32 pooled features of an (N, 3, S, S) float32 batch."""


class TorchBackbone(Backbone):
    """A backbone computed by a torch module (what an inference runtime's export starts from)."""

    @abstractmethod
    def feature_module(self) -> torch.nn.Module:
        """The frozen module mapping an (N, 3, S, S) batch to its (N, feature_dimension) features."""

    @property
    def threads(self) -> int:
        import torch

        return torch.get_num_threads()

    def features(self, batch: np.ndarray) -> np.ndarray:
        import torch  # the backbone's module already imported it; this only binds the name

        with torch.inference_mode():
            tensor = torch.from_numpy(batch).contiguous(memory_format=torch.channels_last)
            return self.feature_module()(tensor).numpy()
