"""The port of frozen image backbones for crop embedding.

A backbone turns a batch of 224 px crops, as uint8 RGB pixels, into one feature vector per crop.
It takes pixels rather than a normalised float batch so that a runtime able to fold the ImageNet
normalisation into its graph does so (OpenVINO: the subtraction and scaling join the first
convolution, and the 600 kB float copy of every crop is never made in NumPy). It is
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
    """A frozen feature extractor: (N, S, S, 3) uint8 RGB pixels -> (N, feature_dimension) float32."""

    feature_dimension: int
    input_size: int = 224
    mean: tuple[float, float, float] = IMAGENET_MEAN
    std: tuple[float, float, float] = IMAGENET_STD

    @property
    def threads(self) -> int:
        """Threads the features are computed with (0 when the runtime does not say)."""
        return 0

    @abstractmethod
    def features(self, pixels: np.ndarray) -> np.ndarray:
        """Return the (N, feature_dimension) float32 pooled features of (N, S, S, 3) uint8 RGB crops
        already resized to :attr:`input_size`, normalising them with :attr:`mean` and :attr:`std`."""

    def normalised(self, pixels: np.ndarray) -> np.ndarray:
        """(N, S, S, 3) float32: the pixels on 0..255 normalised with the ImageNet statistics, channels
        last (what a runtime without its own normalisation feeds its network, transposed as it needs)."""
        batch = np.array(pixels, dtype=np.float32)  # a copy: the caller's pixels stay as they were
        batch -= np.asarray(self.mean, dtype=np.float32) * 255.0
        batch *= 1.0 / (np.asarray(self.std, dtype=np.float32) * 255.0)
        return batch


class TorchBackbone(Backbone):
    """A backbone computed by a torch module (what an inference runtime's export starts from)."""

    @abstractmethod
    def feature_module(self) -> torch.nn.Module:
        """The frozen module mapping an (N, 3, S, S) batch to its (N, feature_dimension) features."""

    @property
    def threads(self) -> int:
        import torch

        return torch.get_num_threads()

    def features(self, pixels: np.ndarray) -> np.ndarray:
        import torch  # the backbone's module already imported it; this only binds the name

        with torch.inference_mode():
            # Channels-last memory viewed as (N, 3, S, S): the layout torch's CPU convolutions prefer.
            tensor = torch.from_numpy(self.normalised(pixels)).permute(0, 3, 1, 2)
            return self.feature_module()(tensor).numpy()
