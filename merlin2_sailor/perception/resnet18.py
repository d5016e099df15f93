"""ResNet-18, the paper's backbone, written in plain torch with torchvision's state-dict names.

torchvision does not install beside the CPU torch build used here, and no package ships
pretrained ResNet-18 weights (two that claim to hold random ones). The network is small enough to
write out; because every module has torchvision's name, a ``resnet18`` weights file saved with
``torch.save(torchvision.models.resnet18(weights=...).state_dict(), path)`` loads into it
unchanged. Features are the 512 average-pooled channels before the classifier.
"""

from __future__ import annotations

from pathlib import Path

import torch
from torch import nn

from merlin2_sailor.errors import ConfigurationError, DependencyError
from merlin2_sailor.perception.backbone import TorchBackbone


class BasicBlock(nn.Module):
    """Two 3x3 convolutions with a shortcut; a 1x1 projection when the shape changes."""

    def __init__(self, in_channels: int, out_channels: int, stride: int) -> None:
        super().__init__()
        self.conv1 = nn.Conv2d(in_channels, out_channels, 3, stride=stride, padding=1, bias=False)
        self.bn1 = nn.BatchNorm2d(out_channels)
        self.relu = nn.ReLU(inplace=True)
        self.conv2 = nn.Conv2d(out_channels, out_channels, 3, stride=1, padding=1, bias=False)
        self.bn2 = nn.BatchNorm2d(out_channels)
        self.downsample: nn.Module | None = None
        if stride != 1 or in_channels != out_channels:
            self.downsample = nn.Sequential(
                nn.Conv2d(in_channels, out_channels, 1, stride=stride, bias=False), nn.BatchNorm2d(out_channels)
            )

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        shortcut = x if self.downsample is None else self.downsample(x)
        out = self.relu(self.bn1(self.conv1(x)))
        out = self.bn2(self.conv2(out))
        return self.relu(out + shortcut)


class ResNet18(nn.Module):
    """torchvision's ``resnet18`` layout, module for module."""

    def __init__(self, number_of_classes: int = 1000) -> None:
        super().__init__()
        self.conv1 = nn.Conv2d(3, 64, 7, stride=2, padding=3, bias=False)
        self.bn1 = nn.BatchNorm2d(64)
        self.relu = nn.ReLU(inplace=True)
        self.maxpool = nn.MaxPool2d(3, stride=2, padding=1)
        self.layer1 = nn.Sequential(BasicBlock(64, 64, 1), BasicBlock(64, 64, 1))
        self.layer2 = nn.Sequential(BasicBlock(64, 128, 2), BasicBlock(128, 128, 1))
        self.layer3 = nn.Sequential(BasicBlock(128, 256, 2), BasicBlock(256, 256, 1))
        self.layer4 = nn.Sequential(BasicBlock(256, 512, 2), BasicBlock(512, 512, 1))
        self.avgpool = nn.AdaptiveAvgPool2d((1, 1))
        self.fc = nn.Linear(512, number_of_classes)

    def pooled_features(self, x: torch.Tensor) -> torch.Tensor:
        x = self.maxpool(self.relu(self.bn1(self.conv1(x))))
        x = self.layer4(self.layer3(self.layer2(self.layer1(x))))
        return torch.flatten(self.avgpool(x), 1)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.fc(self.pooled_features(x))


class PooledResNet18(nn.Module):
    """The 512 pooled channels before the classifier, as a module of its own (what is exported)."""

    def __init__(self, network: ResNet18) -> None:
        super().__init__()
        self.network = network

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.network.pooled_features(x)


class ResNet18Backbone(TorchBackbone):
    """512-d features from a user-supplied torchvision ResNet-18 weights file."""

    feature_dimension = 512

    def __init__(self, weights_path: str = "") -> None:
        if not weights_path:
            raise ConfigurationError(
                "The resnet18 backbone needs weights_path, a torchvision resnet18 state dict (.pth); no package "
                "ships pretrained ResNet-18 weights. Use the efficientnet_lite0 backbone otherwise."
            )
        path = Path(weights_path).expanduser()
        if not path.is_file():
            raise DependencyError(f"ResNet-18 weights file {path} does not exist.")
        state_dict = torch.load(path, map_location="cpu", weights_only=True)
        if not isinstance(state_dict, dict):
            raise ConfigurationError(f"{path} does not hold a state dict (got {type(state_dict).__name__}).")
        # A fine-tuned file may have another classifier size; the classifier is unused but loaded
        # so that a strict load still proves every other tensor is where torchvision puts it.
        classifier = state_dict.get("fc.weight")
        self._network = ResNet18(number_of_classes=classifier.shape[0] if classifier is not None else 1000)
        try:
            self._network.load_state_dict(state_dict, strict=True)
        except RuntimeError as error:
            raise ConfigurationError(
                f"{path} is not a torchvision resnet18 state dict: {' '.join(str(error).split())[:400]}"
            ) from error
        # Channels-last halves the CPU time of these convolutions (oneDNN's preferred layout).
        self._network.eval().requires_grad_(False)
        self._network.to(memory_format=torch.channels_last)  # type: ignore[call-overload]
        self._pooled = PooledResNet18(self._network).eval()

    def feature_module(self) -> torch.nn.Module:
        return self._pooled
