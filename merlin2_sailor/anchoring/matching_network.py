"""The paper's matching network M and the matcher that runs it, with self-describing weights.

Architecture (sizes of the public SAILOR implementation; D is the frozen backbone's feature size,
1280 for EfficientNet-Lite0, 512 for ResNet-18):

- siamese branch: ``|f_p - f_a|`` (D) -> Linear(D, 512) -> ReLU. The backbone itself is not part
  of this module: features arrive pre-computed (and cached on anchors), so each crop goes
  through the backbone once rather than once per pair;
- PerceptAnchor network: one Linear(., 256) + ReLU per feature (same class, siamese output,
  distance, scale, time), concatenated (5 x 256 = 1280) -> Linear(1280, 256) -> ReLU;
- binary classifier: Dropout(0.5) -> Linear(256, 1024) -> ReLU -> Linear(1024, 256) -> ReLU ->
  Linear(256, 1), and a sigmoid.

``forward`` returns logits, so training can use ``BCEWithLogitsLoss`` (numerically safer than a
sigmoid followed by BCELoss); :meth:`MatchingNetwork.probabilities` applies the sigmoid.

A weights file is a ``torch.save`` of ``{"format", "metadata", "state_dict"}``; the metadata say
which backbone and feature encoding the network was trained with, and :func:`load_network`
refuses a file that does not fit, because a network fed features from another backbone or
another time scale outputs confident nonsense rather than an error.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from merlin2_sailor.anchoring.features import FEATURE_ENCODING_VERSION, FeatureConfig, PairFeatures
from merlin2_sailor.anchoring.matcher import Matcher
from merlin2_sailor.anchoring.rule_matcher import RuleMatcher
from merlin2_sailor.errors import ConfigurationError, DependencyError, SailorError

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


@dataclass(frozen=True, slots=True)
class NetworkMetadata:
    """What a set of weights was trained with; stored in, and checked against, the weights file."""

    backbone: str = "efficientnet_lite0"
    feature_dimension: int = 1280
    feature_encoding_version: int = FEATURE_ENCODING_VERSION
    time_scale: float = 30.0
    siamese_units: int = 512
    branch_units: int = 256
    classifier_units: tuple[int, int] = (1024, 256)
    dropout: float = 0.5

    def __post_init__(self) -> None:
        if not self.backbone:
            raise ConfigurationError("network metadata needs a backbone name (e.g. efficientnet_lite0).")
        for name in ("feature_dimension", "siamese_units", "branch_units"):
            if getattr(self, name) < 1:
                raise ConfigurationError(f"network {name} must be at least 1, got {getattr(self, name)}.")
        object.__setattr__(self, "classifier_units", tuple(int(u) for u in self.classifier_units))
        if len(self.classifier_units) != 2 or min(self.classifier_units) < 1:
            raise ConfigurationError(
                f"network classifier_units must be two positive sizes, got {self.classifier_units}."
            )
        if not (0.0 <= self.dropout < 1.0):
            raise ConfigurationError(f"network dropout must be in [0, 1), got {self.dropout}.")
        FeatureConfig(time_scale=self.time_scale)  # validates the time scale

    @property
    def feature_config(self) -> FeatureConfig:
        return FeatureConfig(time_scale=self.time_scale)


def _dense(inputs: int, outputs: int) -> nn.Sequential:
    return nn.Sequential(nn.Linear(inputs, outputs), nn.ReLU(inplace=True))


class MatchingNetwork(nn.Module):
    """The trainable part of M (see the module docstring); batched over N pairs."""

    def __init__(self, metadata: NetworkMetadata | None = None) -> None:
        super().__init__()
        self.metadata = metadata or NetworkMetadata()
        units = self.metadata.branch_units
        self.siamese = _dense(self.metadata.feature_dimension, self.metadata.siamese_units)
        self.same_class_branch = _dense(1, units)
        self.siamese_branch = _dense(self.metadata.siamese_units, units)
        self.distance_branch = _dense(1, units)
        self.scale_branch = _dense(1, units)
        self.time_branch = _dense(1, units)
        self.merge = _dense(5 * units, units)
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
    ) -> torch.Tensor:
        """Return (N,) logits. Scalars are (N,) or (N, 1) encoded features, the difference (N, D)."""
        merged = torch.cat(
            (
                self.same_class_branch(same_class.reshape(-1, 1)),
                self.siamese_branch(self.siamese(appearance_difference)),
                self.distance_branch(distance.reshape(-1, 1)),
                self.scale_branch(scale.reshape(-1, 1)),
                self.time_branch(time.reshape(-1, 1)),
            ),
            dim=1,
        )
        return self.classifier(self.merge(merged)).reshape(-1)

    def probabilities(self, *inputs: torch.Tensor) -> torch.Tensor:
        return torch.sigmoid(self.forward(*inputs))

    def inputs_from(self, features: PairFeatures) -> tuple[torch.Tensor, ...]:
        """The forward's inputs for every pair of ``features`` (appearance rows must be known)."""
        if features.appearance_difference is None:
            raise SailorError("The matching network needs appearance; compute features with with_appearance=True.")
        if features.appearance_difference.shape[1] != self.metadata.feature_dimension:
            raise ConfigurationError(
                f"The matching network expects {self.metadata.feature_dimension}-d {self.metadata.backbone} "
                f"features but got {features.appearance_difference.shape[1]}-d ones; "
                "embed crops with the same backbone."
            )

        def column(values: np.ndarray) -> torch.Tensor:
            return torch.from_numpy(np.ascontiguousarray(values, dtype=np.float32))

        return (
            column(features.same_class),
            column(features.appearance_difference),
            column(features.distance_score),
            column(features.scale),
            column(features.time_score),
        )


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


@dataclass(frozen=True, slots=True)
class NetworkMatcherConfig:
    """``fallback``: scores pairs the network cannot (an anchor or percept with no embedding, e.g.
    a crop-less percept or an anchor restored without its gallery)."""

    fallback: RuleMatcher = field(default_factory=RuleMatcher)


class NetworkMatcher(Matcher):
    """Runs a :class:`MatchingNetwork` on every pair in one batched forward pass."""

    uses_appearance = True

    def __init__(self, network: MatchingNetwork, config: NetworkMatcherConfig | None = None) -> None:
        self.network = network.eval()
        self.config = config or NetworkMatcherConfig()

    @classmethod
    def from_file(cls, path: str | Path, backbone: str, feature_dimension: int | None = None) -> NetworkMatcher:
        return cls(load_network(path, backbone, feature_dimension))

    @property
    def feature_config(self) -> FeatureConfig:
        return self.network.metadata.feature_config

    def score_pairs(self, features: PairFeatures) -> np.ndarray:
        scores = np.zeros(len(features))
        known = features.appearance_known
        if (~known).any():
            scores[~known] = self.config.fallback.score_pairs(features)[~known]
        if known.any():
            inputs = [tensor[torch.from_numpy(known)] for tensor in self.network.inputs_from(features)]
            with torch.inference_mode():
                scores[known] = self.network.probabilities(*inputs).double().numpy()
        return scores

