"""The shipped weights: they load, they were made from the house source, and on held-out houses
(never used in training or model selection) they score pairs far better than the rules and keep
identities as well as the rules do in the demo's house.

The held-out houses are two ``test`` houses of the same house source the weights were
trained on (its ``train`` and ``validation`` splits); crops are embedded with the real backbone.
The F1 asked here (0.97 over two houses) guards against a regression; the figure over ten
houses is the one ``sailor evaluate`` prints (merlin2_sailor/models/__init__.py).
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

torch = pytest.importorskip("torch", reason="pip install torch==2.13.0 (CPU build)")

from merlin2_sailor.anchoring.matching_network import NetworkMatcher, load_network  # noqa: E402
from merlin2_sailor.anchoring.rule_matcher import RuleMatcher, RuleMatcherConfig  # noqa: E402
from merlin2_sailor.models import DEFAULT_BACKBONE, DEFAULT_PROVENANCE_FILE, default_weights_path, models_folder  # noqa: E402
from merlin2_sailor.perception.crop_descriptor import DESCRIPTOR_SIZE  # noqa: E402
from merlin2_sailor.training.embedding_cache import EmbeddingCache  # noqa: E402
from merlin2_sailor.training.generated_dataset import TEST, GeneratedPairSet, default_cache_folder  # noqa: E402
from merlin2_sailor.training.identity_evaluation import evaluate_identities  # noqa: E402
from merlin2_sailor.training.pair_dataset import PairDatasetConfig  # noqa: E402
from merlin2_sailor.training.pair_scoring import evaluate_pairs  # noqa: E402
from merlin2_sailor.training.photo_library import DARKNET_ENVIRONMENT_VARIABLE, DEFAULT_DARKNET_FOLDER  # noqa: E402

#: Test houses 2 and 3 (13 and 14 objects; houses 0 and 1 hold only 8 and 6).
FIRST_HELD_OUT, HELD_OUT_HOUSES = 2, 2
#: The floor of the pair F1 over those houses, a little below what the shipped weights reach there
#: (0.968; on all 10 test houses 0.971). The weights before 4 December's 96 training houses
#: reached 0.977 on the 10 with 32, but anchored worse in the replay (the README).
MINIMUM_F1 = 0.96
#: The demo's rule tolerance (launch/demo.yaml): the rules at their best in that house.
DEMO_RULES = RuleMatcherConfig(maximum_sigma=0.3)

darknet = Path(os.environ.get(DARKNET_ENVIRONMENT_VARIABLE) or DEFAULT_DARKNET_FOLDER)
pytestmark = pytest.mark.skipif(
    not (darknet / "dog.jpg").is_file(),
    reason="the shipped weights were trained with darknet's photos; run scripts/fetch_test_data.sh",
)


def provenance() -> dict:
    return json.loads((models_folder() / DEFAULT_PROVENANCE_FILE).read_text())


@pytest.fixture(scope="module")
def held_out():
    from merlin2_sailor.perception.embedding import CropEmbedder
    from merlin2_sailor_demos.identity.house_source import HouseSource, HouseSourceConfig

    record = provenance()
    houses = default_cache_folder().parent / "houses"
    source = HouseSource(HouseSourceConfig(seed=record["source_config"]["seed"]), houses)
    assert source.fingerprint == record["source_fingerprint"], "the house source changed: remake the weights"
    pair_set = GeneratedPairSet(source, TEST, HELD_OUT_HOUSES, PairDatasetConfig(), FIRST_HELD_OUT)
    embedder = CropEmbedder()
    cache = EmbeddingCache(embedder, embedder.name, default_cache_folder())
    pair_set.embed(cache)
    return pair_set, cache, load_network(default_weights_path(), DEFAULT_BACKBONE)


def test_the_shipped_weights_are_small_and_describe_themselves() -> None:
    path = default_weights_path()
    assert path.stat().st_size < 4 * 2**20
    # The backbone's features, then the crop descriptor.
    network = load_network(path, DEFAULT_BACKBONE, 1280 + DESCRIPTOR_SIZE)
    record = provenance()
    assert record["source"] == "houses" and record["dataset_hash"] and record["backbone"] == network.metadata.backbone
    assert record["splits"]["test"] == 0  # the test split never took part in training


def test_held_out_f1_is_at_least_0_96_and_far_above_the_rules(held_out) -> None:
    pair_set, cache, network = held_out
    counts = evaluate_pairs(NetworkMatcher(network), pair_set.chunks(), cache)
    rules = evaluate_pairs(RuleMatcher(DEMO_RULES), pair_set.chunks(), None)
    for name, result in (("network", counts), ("rules", rules)):
        total = result.all_pairs
        print(f"{name}: held-out pairs {total.total}, positives {total.positives}: precision {total.precision:.4f}, "
              f"recall {total.recall:.4f}, F1 {total.f1:.4f}; partial views F1 {result.partial.f1:.4f}")
    assert counts.all_pairs.positives > 200 and counts.partial.positives > 50
    assert counts.all_pairs.f1 >= MINIMUM_F1
    assert counts.partial.f1 >= MINIMUM_F1 - 0.02
    assert counts.all_pairs.f1 > rules.all_pairs.f1 + 0.05


def test_anchoring_with_the_network_keeps_identities_in_held_out_houses(held_out) -> None:
    """Replayed as the node anchors (cut views scored without their look, the replay told which
    they are), the network makes no more anchors than the rules and identities as good. (Until
    4 December 2026 the replay took every view for whole and the network made 25 anchors of these
    23 objects: a strict xfail. On all 10 held-out houses it makes 170 anchors of 167
    objects, the rules 167: ``sailor evaluate --source houses``.)"""
    pair_set, cache, network = held_out
    with_network = evaluate_identities(lambda: NetworkMatcher(network), pair_set.scenes(), cache)
    with_rules = evaluate_identities(lambda: RuleMatcher(DEMO_RULES), pair_set.scenes())
    print(f"network: {with_network}\nrules: {with_rules}")
    assert with_network.instances == with_rules.instances
    assert with_network.idf1 >= with_rules.idf1
    assert with_network.anchors <= with_rules.anchors


def test_in_the_demos_house_the_network_anchors_no_object_twice_where_the_rules_do_not() -> None:
    # One measurement the network as the default must rest on: the weights trained on photo regions
    # (before the house source) made 6 duplicate anchors on this tour of the kitchen and the living
    # room (the bicycle, both cats, a mug, the television twice) and 5 identity switches; the rules none.
    from merlin2_sailor.perception.embedding import CropEmbedder
    from merlin2_sailor_demos.identity.tour import TourConfig
    from merlin2_sailor_demos.identity.tour_evaluation import MatcherSetup, evaluate_tour
    from merlin2_sailor_demos.world import load_world

    house = Path(__file__).resolve().parents[3] / "config" / "worlds" / "house.yaml"
    network = load_network(default_weights_path(), DEFAULT_BACKBONE)
    scores = evaluate_tour(
        load_world(house),
        {"rules": lambda: MatcherSetup(RuleMatcher(DEMO_RULES)),
         "network": lambda: MatcherSetup(NetworkMatcher(network), CropEmbedder())},
        seed=0, tour=TourConfig(stops=("kitchen", "living_room"), revisit=True),
    )
    print({name: (result.duplicates, result.switches, result.split_objects) for name, result in scores.items()})
    assert scores["network"].duplicates <= scores["rules"].duplicates
    assert scores["network"].switches <= scores["rules"].switches
    assert not scores["network"].split_objects and not scores["network"].merged_symbols


def test_a_views_twin_two_widths_away_is_another_object(held_out) -> None:
    """The same view moved along x to where a neighbour in a row would stand (two of the object's
    widths from its anchor, never less than 0.15 m each; look, size and time unchanged) is
    rejected, while half a width is the anchor's own noise. Before the separation feature most of
    the network's 138 false pairs on the held-out houses were such neighbours (the README)."""
    import dataclasses

    import numpy as np

    from merlin2_sailor.anchoring.features import MINIMUM_SEPARATION_WIDTH
    from merlin2_sailor.training.pair_dataset import PairChunk
    from merlin2_sailor.training.pair_scoring import chunk_features

    pair_set, cache, network = held_out
    matcher = NetworkMatcher(network)
    pairs = PairChunk.concatenate(list(pair_set.chunks()))
    frame_apart = (pairs.labels & ~(pairs.searched | pairs.replaced) & ~pairs.partial
                   & (pairs.percept_stamps - pairs.anchor_last_seen < 1.0))
    views = pairs.take(np.flatnonzero(frame_apart))
    widths = np.maximum(np.maximum(views.anchor_sizes[:, 0], views.percept_sizes[:, 0]), MINIMUM_SEPARATION_WIDTH)

    def accepted(widths_away: float) -> float:
        moved = views.percept_positions.copy()
        moved[:, 0] = views.anchor_positions[:, 0] + widths_away * widths
        moved[:, 1] = views.anchor_positions[:, 1]
        shifted = dataclasses.replace(views, percept_positions=moved)
        scores = matcher.score_pairs(chunk_features(shifted, matcher, cache))
        return float(np.mean(scores >= 0.5))

    assert len(views) > 50
    assert accepted(0.5) > 0.95
    assert accepted(2.0) < 0.1
