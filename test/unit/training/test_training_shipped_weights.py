"""The shipped weights: they load, and on held-out generated scenes (never used in training or
model selection) reach F1 >= 0.97 and beat the rule matcher on look-alikes and in anchoring.

The held-out scenes are the ``test`` split of the same generated source the weights were trained
on (its ``train`` and ``validation`` splits); crops are embedded with the real backbone.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

torch = pytest.importorskip("torch", reason="pip install torch==2.13.0 (CPU build)")

from merlin2_sailor.anchoring.matching_network import NetworkMatcher, load_network  # noqa: E402
from merlin2_sailor.anchoring.rule_matcher import RuleMatcher  # noqa: E402
from merlin2_sailor.models import DEFAULT_BACKBONE, DEFAULT_PROVENANCE_FILE, default_weights_path, models_folder  # noqa: E402
from merlin2_sailor.training.embedding_cache import EmbeddingCache  # noqa: E402
from merlin2_sailor.training.generated_dataset import TEST, GeneratedPairSet  # noqa: E402
from merlin2_sailor.training.generated_scenes import GeneratedSource, GeneratedSourceConfig  # noqa: E402
from merlin2_sailor.training.identity_evaluation import evaluate_identities  # noqa: E402
from merlin2_sailor.training.pair_dataset import PairDatasetConfig  # noqa: E402
from merlin2_sailor.training.pair_scoring import evaluate_pairs  # noqa: E402
from merlin2_sailor.training.photo_library import DARKNET_ENVIRONMENT_VARIABLE, DEFAULT_DARKNET_FOLDER  # noqa: E402

HELD_OUT_SCENES = 10
MINIMUM_F1 = 0.97

darknet = Path(os.environ.get(DARKNET_ENVIRONMENT_VARIABLE) or DEFAULT_DARKNET_FOLDER)
pytestmark = pytest.mark.skipif(
    not (darknet / "dog.jpg").is_file(),
    reason="the shipped weights were trained with darknet's photos; run scripts/fetch_test_data.sh",
)


@pytest.fixture(scope="module")
def held_out():
    from merlin2_sailor.perception.embedding import CropEmbedder

    provenance = json.loads((models_folder() / DEFAULT_PROVENANCE_FILE).read_text())
    source = GeneratedSource(GeneratedSourceConfig(seed=provenance["source_config"]["seed"]))
    assert source.fingerprint == provenance["source_fingerprint"], "the generator changed: remake the weights"
    pair_set = GeneratedPairSet(source, TEST, HELD_OUT_SCENES, PairDatasetConfig())
    cache = EmbeddingCache(CropEmbedder(), DEFAULT_BACKBONE)
    pair_set.embed(cache)
    network = load_network(default_weights_path(), DEFAULT_BACKBONE)
    return pair_set, cache, network


def test_the_shipped_weights_are_small_and_describe_themselves() -> None:
    path = default_weights_path()
    assert path.stat().st_size < 20 * 2**20
    network = load_network(path, DEFAULT_BACKBONE, 1280)
    provenance = json.loads((models_folder() / DEFAULT_PROVENANCE_FILE).read_text())
    assert provenance["dataset_hash"] and provenance["backbone"] == network.metadata.backbone
    assert provenance["splits"]["test"] == 0  # the test split never took part in training


def test_held_out_f1_is_at_least_0_97(held_out) -> None:
    pair_set, cache, network = held_out
    result = evaluate_pairs(NetworkMatcher(network), pair_set.chunks(), cache)
    counts = result.all_pairs
    print(f"held-out pairs {counts.total}, positives {counts.positives}: accuracy {counts.accuracy:.4f}, "
          f"precision {counts.precision:.4f}, recall {counts.recall:.4f}, F1 {counts.f1:.4f}")
    assert counts.positives > 100
    assert counts.f1 >= MINIMUM_F1


def test_the_network_beats_the_rules_on_look_alikes(held_out) -> None:
    pair_set, cache, network = held_out
    network_result = evaluate_pairs(NetworkMatcher(network), pair_set.chunks(), cache).look_alike
    rule_result = evaluate_pairs(RuleMatcher(), pair_set.chunks(), None).look_alike
    print(f"look-alike pairs {network_result.total}: network F1 {network_result.f1:.4f}, rules F1 {rule_result.f1:.4f}")
    assert network_result.total > 100
    assert network_result.f1 > rule_result.f1


def test_anchoring_with_the_network_keeps_identities(held_out) -> None:
    # Inside the whole layer, gating and the one-to-one assignment already resolve most of the
    # look-alike pairs the rules score wrongly, so the margin is small (30 test scenes: IDF1 0.9726
    # vs 0.9720): this guards against a regression rather than claiming a large gain.
    pair_set, cache, network = held_out
    with_network = evaluate_identities(lambda: NetworkMatcher(network), pair_set.scenes(), cache)
    with_rules = evaluate_identities(RuleMatcher, pair_set.scenes())
    print(f"network: {with_network}\nrules: {with_rules}")
    assert with_network.instances == with_rules.instances
    assert with_network.idf1 >= 0.95
    assert with_network.idf1 >= with_rules.idf1 - 0.01
