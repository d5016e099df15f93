"""The anchoring layer: percepts in, anchors (object <-> symbol links) out; ROS-free.

The names below are the public API, imported on first use (PEP 562), so that importing one
small module of this package does not pay for SciPy, the knowledge model or torch.
``NetworkMatcher`` and the other names of :mod:`.matching_network` import torch when first
touched, and only then.
"""

from __future__ import annotations

import importlib
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

#: Public name -> the module defining it.
_EXPORTS = MappingProxyType(
    {
        "Anchor": "anchor",
        "AnchorState": "anchor",
        "AnchorIndex": "anchor_index",
        "IndexConfig": "anchor_index",
        "Anchoring": "anchoring",
        "AnchoringConfig": "anchoring",
        "AnchoringResult": "anchoring",
        "Assignment": "assignment",
        "assign": "assignment",
        "AnchorEvent": "events",
        "AnchorEventKind": "events",
        "Expectation": "expectation",
        "ExpectationKind": "expectation",
        "FEATURE_ENCODING_VERSION": "features",
        "FeatureConfig": "features",
        "PairFeatures": "features",
        "FusionConfig": "fusion",
        "LifecycleConfig": "lifecycle",
        "Matcher": "matcher",
        "MatchingNetwork": "matching_network",
        "NetworkMatcher": "matching_network",
        "NetworkMetadata": "network_inputs",
        "MatchingTable": "matching_table",
        "MatchingTableBuilder": "matching_table",
        "MatchingTableConfig": "matching_table",
        "RuleMatcher": "rule_matcher",
        "RuleMatcherConfig": "rule_matcher",
        "SymbolCounter": "symbols",
        "SymbolFactory": "symbols",
        "CameraView": "visibility",
        "VisibilityConfig": "visibility",
    }
)

__all__ = sorted(_EXPORTS)

if TYPE_CHECKING:
    from merlin2_sailor.anchoring.anchor import Anchor, AnchorState
    from merlin2_sailor.anchoring.anchor_index import AnchorIndex, IndexConfig
    from merlin2_sailor.anchoring.anchoring import Anchoring, AnchoringConfig, AnchoringResult
    from merlin2_sailor.anchoring.assignment import Assignment, assign
    from merlin2_sailor.anchoring.events import AnchorEvent, AnchorEventKind
    from merlin2_sailor.anchoring.expectation import Expectation, ExpectationKind
    from merlin2_sailor.anchoring.features import FEATURE_ENCODING_VERSION, FeatureConfig, PairFeatures
    from merlin2_sailor.anchoring.fusion import FusionConfig
    from merlin2_sailor.anchoring.lifecycle import LifecycleConfig
    from merlin2_sailor.anchoring.matcher import Matcher
    from merlin2_sailor.anchoring.matching_network import MatchingNetwork, NetworkMatcher
    from merlin2_sailor.anchoring.matching_table import MatchingTable, MatchingTableBuilder, MatchingTableConfig
    from merlin2_sailor.anchoring.network_inputs import NetworkMetadata
    from merlin2_sailor.anchoring.rule_matcher import RuleMatcher, RuleMatcherConfig
    from merlin2_sailor.anchoring.symbols import SymbolCounter, SymbolFactory
    from merlin2_sailor.anchoring.visibility import CameraView, VisibilityConfig


def __getattr__(name: str) -> Any:
    module_name = _EXPORTS.get(name)
    if module_name is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{module_name}"), name)
    globals()[name] = value  # later look-ups skip this function
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
