"""The paper's matching network M and the matcher that runs it, with self-describing weights.

Architecture (D is the frozen backbone's feature size, 1280 for EfficientNet-Lite0, 512 for
ResNet-18; K the crop descriptor's, 186, that ends each embedding: histograms of the crop's centre
and surround and a thumbnail of its layout, see :mod:`merlin2_sailor.perception.crop_descriptor`;
S, B, C1 and C2 are sizes of
:class:`NetworkMetadata`):

- siamese branch: ``|f_p - f_a|`` over the backbone's D features -> Linear(D, S) -> ReLU. The
  backbone itself is not part of this module: features arrive pre-computed (and cached on
  anchors), so each crop goes through the backbone once rather than once per pair. While training,
  half of the difference's elements are dropped (``appearance_dropout``, no weights, so the files
  are unchanged): a few hundred objects' views are learnt by heart otherwise, and the held-out
  pairs suffer;
- PerceptAnchor network: one Linear(., B) + ReLU per feature (same class, siamese output,
  distance (two values: metres and object widths apart, see :mod:`.features`), scale,
  time; searched: whether the distance was measured from a searched disc, see
  :mod:`.features`; colour: the intersections of the two crops' centre and surround histograms and their layouts'
  lightness correlation and colour closeness (4 values), from the last K values of the same
  ``|f_p - f_a|``), concatenated (7 x B) -> Linear(7 B, B) -> ReLU;
- binary classifier: Dropout(0.5) -> Linear(B, C1) -> ReLU -> Linear(C1, C2) -> ReLU ->
  Linear(C2, 1), and a sigmoid.

The colour branch is new: the backbone's pooled features hold colour weakly, so the version
without it took the green mug for the red one it had never been shown beside (their features are
as close as two views of the red mug); four values per pair, it adds 1 % to the weights. The
layout's two values came later: neither pooled features nor histograms tell a picture from its
mirror image or from another cut of the same photo (see :mod:`merlin2_sailor.perception.layout_thumbnail`). The
public SAILOR implementation has five feature branches (no searched one, no colour), S = 512, B = 256
and (C1, C2) = (1024, 256): 1.6 million weights. The defaults here are a quarter of each
(S = 256, B = 64, (C1, C2) = (256, 64): 0.4 million): trained on the house source, both reached
the same held-out pair F1 (0.990 and 0.991 over 8 test houses) and the same duplicates and
identity switches on tours of the demo's house (three seeds); the smaller trains in half the
time and ships in a quarter of the bytes.

``forward`` returns logits, so training can use ``BCEWithLogitsLoss`` (numerically safer than a
sigmoid followed by BCELoss); :meth:`MatchingNetwork.probabilities` applies the sigmoid.

A weights file is a ``torch.save`` of ``{"format", "metadata", "state_dict"}``; the metadata say
which backbone and feature encoding the network was trained with, and :func:`load_network`
refuses a file that does not fit, because a network fed features from another backbone or
another time scale outputs confident nonsense rather than an error.
"""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path

import numpy as np

from merlin2_sailor.anchoring.features import FEATURE_ENCODING_VERSION, PairFeatures
from merlin2_sailor.anchoring.network_inputs import (
    DISTANCE_VALUES,
    NetworkMatcherConfig,
    NetworkMetadata,
    PairNetworkMatcher,
    network_inputs,
)
from merlin2_sailor.errors import ConfigurationError, DependencyError, SailorError
from merlin2_sailor.perception.crop_descriptor import DESCRIPTOR_SIMILARITIES

try:
    import torch
    from torch import nn
except ImportError as error:  # pragma: no cover - torch is a pinned requirement
    raise DependencyError(
        f"The matching network needs torch (`pip install torch==2.13.0`, a CPU build); "
        f"use RuleMatcher to run without it: {error}"
    ) from error

#: The value of the ``format`` key of every weights file this module writes.
WEIGHTS_FORMAT = "merlin2_sailor.matching_network"


def _dense(inputs: int, outputs: int) -> nn.Sequential:
    return nn.Sequential(nn.Linear(inputs, outputs), nn.ReLU(inplace=True))


class MatchingNetwork(nn.Module):
    """The trainable part of M (see the module docstring); batched over N pairs."""

    def __init__(self, metadata: NetworkMetadata | None = None) -> None:
        super().__init__()
        self.metadata = metadata or NetworkMetadata()
        units = self.metadata.branch_units
        self.siamese = _dense(self.metadata.backbone_dimension, self.metadata.siamese_units)
        self.same_class_branch = _dense(1, units)
        self.siamese_branch = _dense(self.metadata.siamese_units, units)
        self.distance_branch = _dense(DISTANCE_VALUES, units)
        self.scale_branch = _dense(1, units)
        self.time_branch = _dense(1, units)
        self.search_branch = _dense(1, units)
        self.colour_branch = _dense(DESCRIPTOR_SIMILARITIES, units)
        self.merge = _dense(7 * units, units)
        hidden, last_hidden = self.metadata.classifier_units
        self.classifier = nn.Sequential(
            nn.Dropout(self.metadata.dropout),
            *_dense(units, hidden),
            *_dense(hidden, last_hidden),
            nn.Linear(last_hidden, 1),
        )

    def forward(
        self,
        same_class: torch.Tensor,
        appearance_difference: torch.Tensor,
        distance: torch.Tensor,
        scale: torch.Tensor,
        time: torch.Tensor,
        searched: torch.Tensor,
        colour: torch.Tensor,
    ) -> torch.Tensor:
        """Return (N,) logits. Scalars are (N,) or (N, 1) encoded features, the difference (N, D)
        of the backbone's features only, ``distance`` (N, 2) (its score and the separation's),
        ``colour`` (N, 4) (see :meth:`inputs_from`)."""
        if self.metadata.appearance_dropout and self.training:
            appearance_difference = nn.functional.dropout(appearance_difference, self.metadata.appearance_dropout)
        merged = torch.cat(
            (
                self.same_class_branch(same_class.reshape(-1, 1)),
                self.siamese_branch(self.siamese(appearance_difference)),
                self.distance_branch(distance.reshape(-1, DISTANCE_VALUES)),
                self.scale_branch(scale.reshape(-1, 1)),
                self.time_branch(time.reshape(-1, 1)),
                self.search_branch(searched.reshape(-1, 1)),
                self.colour_branch(colour.reshape(-1, DESCRIPTOR_SIMILARITIES)),
            ),
            dim=1,
        )
        return self.classifier(self.merge(merged)).reshape(-1)

    def probabilities(self, *inputs: torch.Tensor) -> torch.Tensor:
        return torch.sigmoid(self.forward(*inputs))

    def inputs_from(self, features: PairFeatures) -> tuple[torch.Tensor, ...]:
        """The forward's inputs for every pair of ``features``, as tensors (see :func:`.network_inputs`)."""
        return tuple(torch.from_numpy(values) for values in network_inputs(self.metadata, features))


class ProbabilityModule(nn.Module):
    """The network with its sigmoid, in evaluation mode: what an inference runtime exports and runs."""

    def __init__(self, network: MatchingNetwork) -> None:
        super().__init__()
        self.network = network.eval()

    def forward(self, *inputs: torch.Tensor) -> torch.Tensor:
        return self.network.probabilities(*inputs)


def save_network(network: MatchingNetwork, path: str | Path) -> None:
    """Write the weights with their metadata; tensors are moved to the CPU first."""
    state = {name: tensor.detach().cpu() for name, tensor in network.state_dict().items()}
    metadata = asdict(network.metadata)
    metadata["classifier_units"] = list(metadata["classifier_units"])
    torch.save({"format": WEIGHTS_FORMAT, "metadata": metadata, "state_dict": state}, Path(path))


def load_network(path: str | Path, backbone: str, feature_dimension: int | None = None) -> MatchingNetwork:
    """Read a weights file on the CPU (whatever device saved it) and check it fits ``backbone``.

    Raises:
        DependencyError: the file is missing or unreadable.
        ConfigurationError: it is not a matching-network file, or it was trained for another
            backbone, feature size or feature encoding.
    """
    path = Path(path)
    expectation = f"weights trained on {backbone} features"
    if not path.is_file():
        raise DependencyError(
            f"Matching network weights file {path} not found; expected {expectation}. Train a network "
            "(the training tools write such a file) or use the rule matcher."
        )
    try:
        content = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as error:  # torch raises pickle, zip and runtime errors alike
        raise DependencyError(f"Cannot read matching network weights file {path} ({expectation}): {error}") from error
    if not isinstance(content, dict) or content.get("format") != WEIGHTS_FORMAT or "metadata" not in content:
        raise ConfigurationError(
            f"{path} is not a merlin2_sailor matching network file (no {WEIGHTS_FORMAT!r} header); "
            f"expected {expectation}."
        )
    try:
        metadata = NetworkMetadata(**content["metadata"])
    except (TypeError, SailorError) as error:
        raise ConfigurationError(f"{path} has malformed network metadata: {error}") from error
    problems = []
    if metadata.backbone != backbone:
        problems.append(f"it was trained on {metadata.backbone} features, not {backbone}")
    if feature_dimension is not None and metadata.feature_dimension != feature_dimension:
        problems.append(f"it expects {metadata.feature_dimension}-d features, not {feature_dimension}-d")
    if metadata.feature_encoding_version != FEATURE_ENCODING_VERSION:
        problems.append(
            f"its feature encoding is version {metadata.feature_encoding_version}, this code computes "
            f"version {FEATURE_ENCODING_VERSION}"
        )
    if problems:
        raise ConfigurationError(
            f"Matching network weights file {path} does not fit: {'; '.join(problems)}. Expected {expectation}."
        )
    network = MatchingNetwork(metadata)
    try:
        network.load_state_dict(content["state_dict"])
    except (RuntimeError, KeyError, TypeError) as error:
        raise ConfigurationError(
            f"Matching network weights file {path} does not fit its own metadata: {error}"
        ) from error
    return network.eval()


class NetworkMatcher(PairNetworkMatcher):
    """Runs a :class:`MatchingNetwork` in torch on every pair in one batched forward pass (the
    training path, and the ``native`` inference runtime)."""

    def __init__(self, network: MatchingNetwork, config: NetworkMatcherConfig | None = None) -> None:
        super().__init__(network.metadata, config)
        self.network = network.eval()

    @classmethod
    def from_file(cls, path: str | Path, backbone: str, feature_dimension: int | None = None) -> NetworkMatcher:
        return cls(load_network(path, backbone, feature_dimension))

    @property
    def threads(self) -> int:
        return torch.get_num_threads()

    def probabilities(self, inputs: tuple[np.ndarray, ...]) -> np.ndarray:
        with torch.inference_mode():
            return self.network.probabilities(*(torch.from_numpy(values) for values in inputs)).double().numpy()
