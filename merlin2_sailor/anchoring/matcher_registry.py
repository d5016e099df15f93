"""Matching functions chosen by name: one table, lazy imports, one function that builds one.

The anchoring node, ``sailor replay``, ``sailor evaluate`` and the benchmarks choose a matcher by
its name (the ``matcher`` setting). Each name has one :class:`MatcherEntry`: where its class is
(``"module:Class"``, imported only when chosen, so the rules never pay for torch), whether it
compares appearance (then the percepts' crops must be embedded, so an embedder is built with it),
and how it is built from the :class:`MatcherSettings`. Nobody else repeats "the network needs an
embedder": :func:`create_matching` answers it from the table.

A new matching function is one entry here (and, if it takes settings, a field of
:class:`MatcherSettings` plus a row per field in :mod:`.settings`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

from merlin2_sailor.anchoring.matcher import Matcher
from merlin2_sailor.anchoring.matching_table import Embedder
from merlin2_sailor.anchoring.rule_matcher import RuleMatcherConfig
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.inference.settings import InferenceSettings
from merlin2_sailor.models import DEFAULT_BACKBONE
from merlin2_sailor.plugins import PluginTable

#: What to install when the network's runtime is missing.
TORCH_HINT = ("Install OpenVINO and torch (scripts/setup.sh does; torch only to export the models), "
              "or choose the 'rules' matcher.")


@dataclass(frozen=True, slots=True)
class MatcherSettings:
    """Which matching function, and what it is built from.

    ``name``: a key of :data:`MATCHER_ENTRIES`; ``weights``: the network's weights file ("" for the
    shipped ones); ``backbone``: the crop backbone the weights were trained with, which the
    embedder runs; ``rules``: the rule matcher's tolerances, also the network's fallback for pairs
    it cannot score (no embedding); ``inference``: the runtime, device and threads the network and
    the crop backbone run with; ``crop_reuse_tolerance``: grey levels under which a crop takes the
    embedding of a recent crop showing the same pixels, 0 to embed every crop
    (:mod:`merlin2_sailor.perception.crop_reuse`, whose default this is).
    """

    name: str = "network"
    weights: str = ""
    backbone: str = DEFAULT_BACKBONE
    rules: RuleMatcherConfig = field(default_factory=RuleMatcherConfig)
    inference: InferenceSettings = field(default_factory=InferenceSettings)
    crop_reuse_tolerance: float = 2.0

    def __post_init__(self) -> None:
        if self.name not in MATCHER_ENTRIES:
            raise ConfigurationError(
                f"Unknown matcher {self.name!r}; choose one of {', '.join(sorted(MATCHER_ENTRIES))}.")
        if not self.backbone:
            raise ConfigurationError("The matcher's backbone must name the crop backbone (e.g. efficientnet_lite0).")


@dataclass(frozen=True, slots=True)
class MatcherEntry:
    """One matching function: ``target`` (``"module:Class"``), ``needs_embedder`` (it compares
    appearance, so crops must be embedded; the class's ``uses_appearance`` says the same, and a
    test holds them together), ``build`` (the loaded class and the settings -> a matcher) and
    ``hint`` (what to install when its import fails)."""

    target: str
    needs_embedder: bool
    build: Callable[[Any, MatcherSettings, Callable[[str], None] | None], Matcher]
    hint: str = ""


def _build_rules(matcher_class: Any, settings: MatcherSettings,
                 report: Callable[[str], None] | None = None) -> Matcher:
    return matcher_class(settings.rules)


def _build_network(matcher_class: Any, settings: MatcherSettings,
                   report: Callable[[str], None] | None = None) -> Matcher:
    """The network on the configured runtime: exported and run by OpenVINO (no torch at run time
    once exported), or in torch itself (``native``)."""
    from merlin2_sailor.anchoring.network_inputs import NetworkMatcherConfig
    from merlin2_sailor.anchoring.rule_matcher import RuleMatcher
    from merlin2_sailor.models import default_weights_path

    weights = Path(settings.weights).expanduser() if settings.weights else default_weights_path()
    # Pairs without an embedding are scored by the rules the deployment configured, not the defaults.
    fallback = NetworkMatcherConfig(fallback=RuleMatcher(settings.rules))
    if settings.inference.runtime == "openvino":
        from merlin2_sailor.anchoring.openvino_matcher import OpenVinoNetworkMatcher

        return OpenVinoNetworkMatcher.from_weights(weights, settings.backbone, settings.inference, fallback, report)
    from merlin2_sailor.anchoring.matching_network import NetworkMatcher, load_network

    settings.inference.apply_to_torch()
    return NetworkMatcher(load_network(weights, settings.backbone), fallback)


MATCHER_ENTRIES: Mapping[str, MatcherEntry] = MappingProxyType({
    "rules": MatcherEntry("merlin2_sailor.anchoring.rule_matcher:RuleMatcher", False, _build_rules),
    "network": MatcherEntry("merlin2_sailor.anchoring.network_inputs:PairNetworkMatcher", True, _build_network,
                            TORCH_HINT),
})

MATCHERS = PluginTable(
    "matcher",
    {name: entry.target for name, entry in MATCHER_ENTRIES.items()},
    hints={name: entry.hint for name, entry in MATCHER_ENTRIES.items() if entry.hint},
)


def create_matcher(settings: MatcherSettings, report: Callable[[str], None] | None = None) -> Matcher:
    """The matcher ``settings.name`` names, built from ``settings`` (its module imported now);
    ``report`` hears what a node should log (a model exported, a device replaced by the CPU)."""
    return MATCHER_ENTRIES[settings.name].build(MATCHERS.load(settings.name), settings, report)


def create_embedder(settings: MatcherSettings, report: Callable[[str], None] | None = None) -> Embedder:
    """The crop embedder running ``settings.backbone`` on ``settings.inference``'s runtime, reusing
    the embedding of a recent crop that shows the same pixels (``settings.crop_reuse_tolerance``)."""
    from merlin2_sailor.perception.crop_reuse import CropReuseConfig, ReusingEmbedder
    from merlin2_sailor.perception.embedding import CropEmbedder, EmbeddingConfig

    embedder = CropEmbedder(EmbeddingConfig(backbone=settings.backbone, inference=settings.inference), report=report)
    return ReusingEmbedder(embedder, CropReuseConfig(tolerance=settings.crop_reuse_tolerance))


def create_matching(settings: MatcherSettings, embed: bool = True,
                    report: Callable[[str], None] | None = None) -> tuple[Matcher, Embedder | None]:
    """(matcher, embedder): the embedder only when the matcher compares appearance and ``embed``
    is set (an offline evaluation whose percepts carry cached embeddings needs none)."""
    matcher = create_matcher(settings, report)
    needs_embedder = MATCHER_ENTRIES[settings.name].needs_embedder
    return matcher, (create_embedder(settings, report) if needs_embedder and embed else None)
