"""Matchers by name: one table, lazy imports, and "needs an embedder" said once, by the table."""

from __future__ import annotations

import subprocess
import sys

import pytest

from merlin2_sailor.anchoring.matcher_registry import (
    MATCHER_ENTRIES,
    MATCHERS,
    MatcherSettings,
    create_matcher,
    create_matching,
)
from merlin2_sailor.anchoring.rule_matcher import RuleMatcher, RuleMatcherConfig
from merlin2_sailor.anchoring.settings import SETTINGS_BY_NAME
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.inference.settings import InferenceSettings


def test_each_entry_says_what_its_class_says_about_appearance() -> None:
    for name, entry in MATCHER_ENTRIES.items():
        assert entry.needs_embedder is MATCHERS.load(name).uses_appearance, name
    # The matcher setting offers exactly the registered names.
    assert SETTINGS_BY_NAME["matcher"].choices == tuple(sorted(MATCHER_ENTRIES))


def test_the_rules_are_built_from_the_settings_and_need_no_embedder() -> None:
    rules = RuleMatcherConfig(position_sigma=0.2, maximum_sigma=0.4)
    matcher, embedder = create_matching(MatcherSettings(name="rules", rules=rules))
    assert isinstance(matcher, RuleMatcher) and matcher.config == rules
    assert embedder is None


def test_choosing_the_rules_never_imports_torch() -> None:
    code = ("import sys; from merlin2_sailor.anchoring.matcher_registry import MatcherSettings, create_matching; "
            "create_matching(MatcherSettings()); print('torch' in sys.modules)")
    printed = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True)
    assert printed.stdout.strip() == "False"


@pytest.mark.parametrize("runtime", ["openvino", "native"])
def test_the_network_loads_the_weights_and_falls_back_on_the_configured_rules(tmp_path, runtime) -> None:
    torch = pytest.importorskip("torch")
    from merlin2_sailor.anchoring.matching_network import NetworkMatcher
    from merlin2_sailor.anchoring.openvino_matcher import OpenVinoNetworkMatcher

    rules = RuleMatcherConfig(maximum_sigma=0.3)
    inference = InferenceSettings(runtime=runtime, threads=1)
    matcher = create_matcher(MatcherSettings(name="network", rules=rules, inference=inference))
    assert isinstance(matcher, {"openvino": OpenVinoNetworkMatcher, "native": NetworkMatcher}[runtime])
    assert matcher.config.fallback.config == rules
    # Only an evaluation whose percepts carry cached embeddings asks for no embedder.
    assert create_matching(MatcherSettings(name="network", inference=inference), embed=False)[1] is None
    # The weights setting is the file read.
    torch.save({"state_dict": {}}, tmp_path / "weights.pt")
    with pytest.raises(ConfigurationError, match="weights.pt is not a merlin2_sailor matching network file"):
        create_matcher(MatcherSettings(name="network", weights=str(tmp_path / "weights.pt"), inference=inference))


def test_an_unknown_matcher_lists_the_known_ones() -> None:
    with pytest.raises(ConfigurationError, match="Unknown matcher 'neural'; choose one of network, rules"):
        MatcherSettings(name="neural")
