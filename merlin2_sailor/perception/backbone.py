"""Frozen image backbones for crop embedding, chosen by name and imported only when chosen.

A backbone turns a batch of normalised 224 px crops into one feature vector per crop. It is
frozen: SAILOR's matching network trains on top of it, never through it. torch is imported by
the backbone modules themselves, so this module (and a deployment without torch) stays light.
"""

from __future__ import annotations

import importlib
from abc import ABC, abstractmethod
from types import MappingProxyType
from typing import TYPE_CHECKING

from merlin2_sailor.errors import ConfigurationError, DependencyError

if TYPE_CHECKING:
    import torch

#: Backbone name -> "module:class"; strings so that choosing one imports only that one.
BACKBONES = MappingProxyType(
    {
        "efficientnet_lite0": "merlin2_sailor.perception.efficientnet_lite0:EfficientNetLite0Backbone",
        "resnet18": "merlin2_sailor.perception.resnet18:ResNet18Backbone",
    }
)

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


def create_backbone(name: str, weights_path: str = "") -> Backbone:
    """Build the backbone called ``name``; ``weights_path`` is needed by those without bundled weights."""
    if name not in BACKBONES:
        raise ConfigurationError(f"Unknown backbone {name!r}; choose one of {', '.join(sorted(BACKBONES))}.")
    module_name, class_name = BACKBONES[name].split(":")
    try:
        module = importlib.import_module(module_name)
    except ImportError as error:
        raise DependencyError(
            f"The {name} backbone needs torch (`pip install torch==2.13.0`, a CPU build): {error}"
        ) from error
    return getattr(module, class_name)(weights_path)
