"""The house source: reproducible scenes, cached once, crops as the camera cut them, anchors as the layer holds them."""

from __future__ import annotations

import numpy as np
import pytest

from merlin2_sailor.training.pair_dataset import PairDatasetConfig, scene_pairs
from merlin2_sailor_demos.identity.house_source import HouseSource, HouseSourceConfig
from merlin2_sailor_demos.identity.tour import TourConfig

from .conftest import SMALL_HOUSES

CONFIG = HouseSourceConfig(houses=SMALL_HOUSES, tour=TourConfig(rate_hz=3.0, track=False))


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    folder = tmp_path_factory.mktemp("houses")
    source = HouseSource(CONFIG, folder)
    return source, source.scene("train", 0), folder


def test_a_scene_is_cached_and_read_back_the_same(made) -> None:
    source, scene, folder = made
    assert list(folder.glob(f"{source.fingerprint}/train-0.json"))
    again = HouseSource(CONFIG, folder).scene("train", 0)
    first, second = list(scene.observations), list(again.observations)
    assert [o.crop_id for o in first] == [o.crop_id for o in second]
    for a, b in zip(first, second, strict=True):
        np.testing.assert_allclose(a.position, b.position)
        np.testing.assert_allclose(a.anchor_position, b.anchor_position)
        assert (a.partial, a.gallery, a.instance, a.twin) == (b.partial, b.gallery, b.instance, b.twin)


def test_crops_render_again_the_same_after_a_reload(made) -> None:
    source, scene, folder = made
    observation = list(scene.observations)[len(list(scene.observations)) // 2]
    crop = source.render(observation)
    fresh = HouseSource(CONFIG, folder)
    np.testing.assert_array_equal(fresh.render(observation), crop)
    assert crop.ndim == 3 and crop.shape[2] == 3 and observation.view.pixels == (crop.shape[1], crop.shape[0])


def test_splits_are_different_houses(made) -> None:
    source, scene, _ = made
    train, _ = source.house("train", 0)
    test, _ = source.house("test", 0)
    assert [spec.xy for spec in train.objects] != [spec.xy for spec in test.objects]


def test_observations_carry_the_anchor_the_layer_would_hold(made) -> None:
    _, scene, _ = made
    observations = list(scene.observations)
    assert len(observations) > 30
    assert any(o.partial for o in observations) and not all(o.partial for o in observations)
    by_instance: dict[int, list] = {}
    for o in observations:
        by_instance.setdefault(o.instance, []).append(o)
    for views in by_instance.values():
        for number, view in enumerate(views):
            # the gallery holds this view and the ones just before it, newest last, at most four
            assert view.gallery[-1] == view.crop_id
            assert list(view.gallery) == [v.crop_id for v in views[max(0, number - 3): number + 1]]
    chunk = scene_pairs(scene, PairDatasetConfig())
    assert chunk.labels.sum() > 20 and chunk.partial.any()
