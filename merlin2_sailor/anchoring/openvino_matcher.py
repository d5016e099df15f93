"""The matching network run by OpenVINO, from a model exported once from its weights file.

The exported model is the torch network with its sigmoid (:class:`~.matching_network.ProbabilityModule`)
in evaluation mode, with the network's metadata written beside it, so this module runs without
torch: it finds the export by the hash of the weights file, checks the metadata as
:func:`~.matching_network.load_network` checks a weights file, and scores through the same
:class:`~.network_inputs.PairNetworkMatcher` shell as the torch matcher (same inputs, same fallback
to the rules). A parity test holds the two within 1e-5 on the same pairs.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict
from pathlib import Path

import numpy as np

from merlin2_sailor.anchoring.features import FEATURE_ENCODING_VERSION
from merlin2_sailor.anchoring.network_inputs import (
    DISTANCE_VALUES,
    INPUT_NAMES,
    NetworkMatcherConfig,
    NetworkMetadata,
    PairNetworkMatcher,
)
from merlin2_sailor.errors import ConfigurationError, DependencyError
from merlin2_sailor.inference.model_cache import MODEL_FILE, ExportedModel, ensure_exported, fingerprint
from merlin2_sailor.inference.openvino_runtime import CompiledNetwork
from merlin2_sailor.inference.settings import InferenceSettings
from merlin2_sailor.perception.crop_descriptor import DESCRIPTOR_SIMILARITIES

MODEL_NAME = "matching-network"


def ensure_matching_network(weights: Path, backbone: str, folder: Path | None = None,
                            report: Callable[[str], None] | None = None) -> ExportedModel:
    """The exported network of ``weights`` (checked against ``backbone``), converted first when missing."""
    weights = Path(weights)
    if not weights.is_file():
        raise DependencyError(f"Matching network weights file {weights} not found.")

    def write(target: Path) -> dict[str, object]:
        import torch

        from merlin2_sailor.anchoring.matching_network import ProbabilityModule, load_network
        from merlin2_sailor.inference.torch_export import save_torch_module

        network = load_network(weights, backbone)
        metadata = network.metadata
        example = (torch.zeros(2), torch.zeros(2, metadata.backbone_dimension), torch.zeros(2, DISTANCE_VALUES),
                   torch.zeros(2), torch.zeros(2), torch.zeros(2), torch.zeros(2, DESCRIPTOR_SIMILARITIES))
        shapes = [(-1,), (-1, metadata.backbone_dimension), (-1, DISTANCE_VALUES), (-1,), (-1,), (-1,),
                  (-1, DESCRIPTOR_SIMILARITIES)]
        save_torch_module(ProbabilityModule(network), example, shapes, target / MODEL_FILE, INPUT_NAMES)
        recorded = asdict(metadata)
        recorded["classifier_units"] = list(recorded["classifier_units"])
        return {"network": recorded, "weights": str(weights)}

    return ensure_exported(MODEL_NAME, fingerprint(backbone, weights), write, f"matching network {weights.name}",
                           needs_torch=True, folder=folder, report=report)


class OpenVinoNetworkMatcher(PairNetworkMatcher):
    """Scores pairs with an exported matching network compiled for the configured device and threads."""

    def __init__(self, exported: ExportedModel, settings: InferenceSettings,
                 config: NetworkMatcherConfig | None = None, report: Callable[[str], None] | None = None) -> None:
        settings.require_float("matching network")
        try:
            metadata = NetworkMetadata(**exported.metadata["network"])
        except (KeyError, TypeError) as error:
            raise ConfigurationError(f"{exported.folder} has no readable network metadata: {error}") from error
        if metadata.feature_encoding_version != FEATURE_ENCODING_VERSION:
            raise ConfigurationError(
                f"The exported network in {exported.folder} uses feature encoding {metadata.feature_encoding_version}; "
                f"this code computes version {FEATURE_ENCODING_VERSION}. Export the weights again.")
        super().__init__(metadata, config)
        self.network = CompiledNetwork(exported.model_path, settings, report)

    @classmethod
    def from_weights(cls, weights: Path, backbone: str, settings: InferenceSettings,
                     config: NetworkMatcherConfig | None = None,
                     report: Callable[[str], None] | None = None) -> OpenVinoNetworkMatcher:
        matcher = cls(ensure_matching_network(weights, backbone, report=report), settings, config, report)
        if matcher.metadata.backbone != backbone:
            raise ConfigurationError(
                f"Matching network weights {weights} were trained on {matcher.metadata.backbone} features, "
                f"not {backbone}.")
        return matcher

    @property
    def threads(self) -> int:
        return self.network.threads

    def probabilities(self, inputs: tuple[np.ndarray, ...]) -> np.ndarray:
        return self.network(*inputs)[0]
