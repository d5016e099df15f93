"""A crop backbone run by OpenVINO from a model exported once from its torch definition.

On two CPU cores OpenVINO computes EfficientNet-Lite0's features 3-5 times faster than torch eager
and loads without torch (figures: ``sailor bench inference``). The exported model is the torch
backbone's own feature module, converted with its weights, so the features agree with torch's to
float32 rounding (a parity test holds them within 1e-4 of the largest feature).

Exporting needs torch; finding and running an exported model does not: a node looks the model up
by the hash of the backbone's weights file (:mod:`merlin2_sailor.inference.model_cache`) and
exports it only when it is missing and torch is importable.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from merlin2_sailor.errors import DependencyError
from merlin2_sailor.inference.model_cache import MODEL_FILE, ExportedModel, ensure_exported, fingerprint
from merlin2_sailor.inference.openvino_runtime import CompiledNetwork
from merlin2_sailor.inference.settings import InferenceSettings
from merlin2_sailor.perception.backbone import Backbone, TorchBackbone
from merlin2_sailor.perception.backbone_weights import backbone_weights_file


def backbone_model_name(name: str) -> str:
    return f"backbone-{name}"


def backbone_fingerprint(name: str, weights_path: str = "") -> str:
    return fingerprint(name, backbone_weights_file(name, weights_path))


#: Builds the torch backbone an export starts from (the registry's, handed in by whoever has it).
TorchBackboneFactory = Callable[[], Backbone]


def ensure_backbone(name: str, build_torch: TorchBackboneFactory, weights_path: str = "",
                    folder: Path | None = None, report: Callable[[str], None] | None = None) -> ExportedModel:
    """The exported backbone ``name``, converted first (``build_torch()``: the torch backbone with its
    weights) when the cache lacks it."""

    def write(target: Path) -> dict[str, object]:
        import torch

        from merlin2_sailor.inference.torch_export import save_torch_module

        backbone = build_torch()
        if not isinstance(backbone, TorchBackbone):
            raise DependencyError(f"The {name} backbone is not a torch module and cannot be exported.")
        size = backbone.input_size
        save_torch_module(backbone.feature_module(), torch.zeros(1, 3, size, size), [(-1, 3, size, size)],
                          target / MODEL_FILE, ["crops"])
        return {"backbone": name, "feature_dimension": backbone.feature_dimension, "input_size": size,
                "mean": list(backbone.mean), "std": list(backbone.std)}

    return ensure_exported(backbone_model_name(name), backbone_fingerprint(name, weights_path), write,
                           f"the {name} backbone", needs_torch=True, folder=folder, report=report)


class OpenVinoBackbone(Backbone):
    """An exported backbone compiled for the configured device and threads."""

    def __init__(self, exported: ExportedModel, settings: InferenceSettings,
                 report: Callable[[str], None] | None = None) -> None:
        settings.require_float("crop backbone")
        metadata = exported.metadata
        self.name = str(metadata["backbone"])
        self.feature_dimension = int(metadata["feature_dimension"])
        self.input_size = int(metadata["input_size"])
        self.mean = tuple(float(value) for value in metadata["mean"])  # type: ignore[assignment]
        self.std = tuple(float(value) for value in metadata["std"])  # type: ignore[assignment]
        self.network = CompiledNetwork(exported.model_path, settings, report)

    @classmethod
    def for_backbone(cls, name: str, weights_path: str, settings: InferenceSettings, build_torch: TorchBackboneFactory,
                     report: Callable[[str], None] | None = None) -> OpenVinoBackbone:
        return cls(ensure_backbone(name, build_torch, weights_path, report=report), settings, report)

    @property
    def threads(self) -> int:
        return self.network.threads

    def features(self, batch: np.ndarray) -> np.ndarray:
        return self.network(np.asarray(batch, dtype=np.float32))[0]
