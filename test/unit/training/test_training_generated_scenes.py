"""The generated source: deterministic, real photo crops, look-alikes, disjoint splits."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.training.generated_scenes import GeneratedSource, GeneratedSourceConfig, SceneConfig
from merlin2_sailor.training.photo_library import PhotoLibrary


@pytest.fixture(scope="module")
def source() -> GeneratedSource:
    # scikit-image's photos only: these tests must not depend on the darknet package.
    return GeneratedSource(GeneratedSourceConfig(seed=3, use_darknet=False))


def test_the_same_seed_generates_the_same_scene_and_crops(source) -> None:
    again = GeneratedSource(GeneratedSourceConfig(seed=3, use_darknet=False), source.library)
    first, second = source.scene("train", 2), again.scene("train", 2)
    pairs = list(zip(first.observations, second.observations, strict=True))
    assert pairs
    for a, b in pairs[:10]:
        assert a.crop_id == b.crop_id and a.instance == b.instance
        np.testing.assert_array_equal(a.position, b.position)
        np.testing.assert_array_equal(source.render(a), again.render(b))


def test_crops_are_real_photo_pixels_changed_per_view(source) -> None:
    scene = source.scene("train", 0)
    by_instance: dict[int, list] = {}
    for observation in scene.observations:
        by_instance.setdefault(observation.instance, []).append(observation)
    views = next(v for v in by_instance.values() if len(v) >= 2)
    first, second = source.render(views[0]), source.render(views[1])
    for crop in (first, second):
        assert crop.dtype == np.uint8 and crop.ndim == 3 and crop.shape[2] == 3
        assert crop.std() > 5.0  # textured, not a flat colour
    assert views[0].view != views[1].view


def test_scenes_have_same_class_look_alikes_and_twins(source) -> None:
    scenes = list(source.scenes("train", 10))
    observations = [o for scene in scenes for o in scene.observations]
    assert any(o.twin for o in observations)
    for scene in scenes[:3]:
        classes = [o.class_name for o in scene.observations]
        instances = {o.instance: o.class_name for o in scene.observations}
        assert len(set(instances.values())) < len(instances), "some class has several instances"
        assert len(classes) > len(instances), "objects are seen more than once"


def test_splits_are_disjoint_scenes(source) -> None:
    train = {o.crop_id for scene in source.scenes("train", 3) for o in scene.observations}
    test = {o.crop_id for scene in source.scenes("test", 3) for o in scene.observations}
    assert train.isdisjoint(test)
    first_positions = source.scene("train", 0).samples[0].observations[0].position
    assert not np.allclose(first_positions, source.scene("test", 0).samples[0].observations[0].position)


def test_the_camera_moves_and_time_advances(source) -> None:
    scene = source.scene("validation", 1)
    stamps = [sample.stamp for sample in scene.samples]
    assert all(b > a for a, b in zip(stamps, stamps[1:], strict=False))
    positions = np.array([sample.camera_to_world.translation for sample in scene.samples])
    assert np.ptp(positions[:, :2], axis=0).max() > 1.0


def test_configurations_are_validated() -> None:
    with pytest.raises(ConfigurationError, match="samples"):
        SceneConfig(samples=1)
    with pytest.raises(ConfigurationError, match="twin_probability"):
        SceneConfig(twin_probability=1.5)
    with pytest.raises(ConfigurationError, match="split"):
        GeneratedSource(GeneratedSourceConfig(use_darknet=False), PhotoLibrary.load(use_darknet=False)).scene("a/b", 0)
    assert dataclasses.is_dataclass(SceneConfig())
