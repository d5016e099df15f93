"""The port of frozen image backbones for crop embedding.

A backbone turns a batch of normalised 224 px crops into one feature vector per crop. It is
frozen: SAILOR's matching network trains on top of it, never through it. torch is imported by
the backbone modules themselves, so this module (and a deployment without torch) stays light;
they are chosen by name in :mod:`.backbone_registry`.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import TYPE_CHECKING

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

    @abstractmethod
    def features(self, batch: torch.Tensor) -> torch.Tensor:
        """Return the pooled features of a batch, without gradients."""
