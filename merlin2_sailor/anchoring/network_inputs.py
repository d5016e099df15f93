"""What the matching network reads, without torch: its metadata, its inputs, and the matcher shell.

The network itself (:mod:`.matching_network`) is torch, for training; at run time the same
network may run exported through an inference runtime (:mod:`.openvino_matcher`). Both take the
same seven inputs computed here from :class:`~.features.PairFeatures`, and both score through
:class:`PairNetworkMatcher`, so the two paths cannot drift apart in what they feed the network or
in how pairs without an embedding fall back to the rules.
"""

from __future__ import annotations

from abc import abstractmethod
from dataclasses import dataclass, field

import numpy as np

from merlin2_sailor.anchoring.features import FEATURE_ENCODING_VERSION, FeatureConfig, PairFeatures
from merlin2_sailor.anchoring.matcher import Matcher
from merlin2_sailor.anchoring.rule_matcher import RuleMatcher
from merlin2_sailor.errors import ConfigurationError, SailorError
from merlin2_sailor.perception.crop_descriptor import DESCRIPTOR_SIMILARITIES, DESCRIPTOR_SIZE, descriptor_similarity

#: The network's inputs in the order of its forward pass (also the exported model's input names).
INPUT_NAMES = ("same_class", "appearance_difference", "distance", "scale", "time", "searched", "colour")
#: Values of the distance input per pair: the distance score and the separation score (see
#: :mod:`.features`), read by one branch, as the paper's distance is.
DISTANCE_VALUES = 2


@dataclass(frozen=True, slots=True)
class NetworkMetadata:
    """What a set of weights was trained with; stored in, and checked against, the weights file."""

    backbone: str = "efficientnet_lite0"
    feature_dimension: int = 1280 + DESCRIPTOR_SIZE  # the whole embedding, crop descriptor included
    colour_bins: int = DESCRIPTOR_SIZE  # its last values, the crop descriptor (0: none)
    feature_encoding_version: int = FEATURE_ENCODING_VERSION
    time_scale: float = 30.0
    siamese_units: int = 256
    branch_units: int = 64
    classifier_units: tuple[int, int] = (256, 64)
    dropout: float = 0.5
    appearance_dropout: float = 0.5

    def __post_init__(self) -> None:
        if not self.backbone:
            raise ConfigurationError("network metadata needs a backbone name (e.g. efficientnet_lite0).")
        for name in ("feature_dimension", "siamese_units", "branch_units"):
            if getattr(self, name) < 1:
                raise ConfigurationError(f"network {name} must be at least 1, got {getattr(self, name)}.")
        if self.colour_bins not in (0, DESCRIPTOR_SIZE) or self.colour_bins >= self.feature_dimension:
            raise ConfigurationError(
                f"network colour_bins must be 0 or {DESCRIPTOR_SIZE} (the crop descriptor's size) and "
                f"below feature_dimension {self.feature_dimension}, got {self.colour_bins}."
            )
        object.__setattr__(self, "classifier_units", tuple(int(u) for u in self.classifier_units))
        if len(self.classifier_units) != 2 or min(self.classifier_units) < 1:
            raise ConfigurationError(
                f"network classifier_units must be two positive sizes, got {self.classifier_units}."
            )
        for name in ("dropout", "appearance_dropout"):
            if not (0.0 <= getattr(self, name) < 1.0):
                raise ConfigurationError(f"network {name} must be in [0, 1), got {getattr(self, name)}.")
        FeatureConfig(time_scale=self.time_scale)  # validates the time scale

    @property
    def feature_config(self) -> FeatureConfig:
        return FeatureConfig(time_scale=self.time_scale)

    @property
    def backbone_dimension(self) -> int:
        """The embedding's values before its crop descriptor: the siamese branch's input."""
        return self.feature_dimension - self.colour_bins


def network_inputs(metadata: NetworkMetadata, features: PairFeatures) -> tuple[np.ndarray, ...]:
    """The network's float32 inputs for every pair of ``features`` (appearance rows must be known),
    in :data:`INPUT_NAMES` order: the embedding difference is split into the backbone's part and
    the similarities of the two crops' descriptors (colour and layout); the distance is (N, :data:`DISTANCE_VALUES`)."""
    if features.appearance_difference is None:
        raise SailorError("The matching network needs appearance; compute features with with_appearance=True.")
    if features.appearance_difference.shape[1] != metadata.feature_dimension:
        raise ConfigurationError(
            f"The matching network expects {metadata.feature_dimension}-d {metadata.backbone} "
            f"features but got {features.appearance_difference.shape[1]}-d ones; "
            "embed crops with the same backbone."
        )

    def column(values: np.ndarray) -> np.ndarray:
        return np.ascontiguousarray(values, dtype=np.float32)

    backbone = metadata.backbone_dimension
    difference = features.appearance_difference
    colour = (descriptor_similarity(difference[:, backbone:]) if metadata.colour_bins
              else np.ones((len(difference), DESCRIPTOR_SIMILARITIES)))
    return (
        column(features.same_class),
        column(difference[:, :backbone]),
        column(np.stack((features.distance_score, features.separation_score), axis=1)),
        column(features.scale),
        column(features.time_score),
        column(features.searched),
        column(colour),
    )


@dataclass(frozen=True, slots=True)
class NetworkMatcherConfig:
    """``fallback``: scores pairs the network cannot (an anchor or percept with no embedding, e.g.
    a crop-less percept or an anchor restored without its gallery)."""

    fallback: RuleMatcher = field(default_factory=RuleMatcher)


class PairNetworkMatcher(Matcher):
    """Scores every pair with known appearance in one batched call of the network, the rest by the
    fallback rules; subclasses say how the network runs (:meth:`probabilities`)."""

    uses_appearance = True

    def __init__(self, metadata: NetworkMetadata, config: NetworkMatcherConfig | None = None) -> None:
        self.metadata = metadata
        self.config = config or NetworkMatcherConfig()

    @property
    def feature_config(self) -> FeatureConfig:
        return self.metadata.feature_config

    @abstractmethod
    def probabilities(self, inputs: tuple[np.ndarray, ...]) -> np.ndarray:
        """(N,) match probabilities for the network's inputs (:func:`network_inputs`)."""

    def score_pairs(self, features: PairFeatures) -> np.ndarray:
        scores = np.zeros(len(features))
        known = features.appearance_known
        if (~known).any():
            scores[~known] = self.config.fallback.score_pairs(features)[~known]
        if known.any():
            inputs = tuple(values[known] for values in network_inputs(self.metadata, features))
            scores[known] = np.asarray(self.probabilities(inputs), dtype=np.float64).reshape(-1)
        return scores
