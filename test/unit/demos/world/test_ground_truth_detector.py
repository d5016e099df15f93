"""Ground-truth detections: boxes on the projection, and seeded misses and false positives."""

from __future__ import annotations

import numpy as np
import pytest

from merlin2_sailor_demos.world.ground_truth_detector import DetectorNoise, GroundTruthDetector
from merlin2_sailor_demos.world.world import World

from .worlds import mug, room_world

EXACT = DetectorNoise(box_noise=0.0, miss_probability=0.0, false_positives_per_frame=0.0)


def _world(noise: DetectorNoise = EXACT, seed: int = 0, objects=None) -> World:
    objects = objects if objects is not None else [mug("a", 3.5, 1.6), mug("b", 3.0, 2.5, size=(0.2, 0.2, 0.4))]
    return World(room_world(objects=objects, size=(5.0, 4.0)), seed=seed, detector_noise=noise)


def test_the_box_is_the_projection_of_the_object() -> None:
    world = _world()
    frame = world.render()
    detections = world.detect(frame)
    assert sorted(d.class_name for d in detections) == ["cup", "cup"]
    intrinsics, camera = world.camera.intrinsics, world.camera_pose(estimated=False)
    expected = []
    for item in world.objects:  # pixel centres are at integer coordinates, box edges half a pixel out
        pixels, _ = intrinsics.project(camera.inverse().transform_points(item.box.corners()))
        box = (pixels[:, 0].min() + 0.5, pixels[:, 1].min() + 0.5, pixels[:, 0].max() + 0.5, pixels[:, 1].max() + 0.5)
        expected.append(np.clip(box, 0.0, [640, 480, 640, 480]))  # the image cuts the box
    for detection in detections:
        nearest = min(expected, key=lambda box: np.abs(np.subtract(box, detection.box.corners)).sum())
        np.testing.assert_allclose(detection.box.corners, nearest, atol=1.0)
        assert detection.class_id == 47 and 0.5 < detection.score <= 0.99


def test_without_a_frame_geometry_gives_the_same_boxes() -> None:
    world = _world()
    from_frame = sorted(d.box.corners for d in world.detect(world.render()))
    from_geometry = sorted(d.box.corners for d in world.detect())
    np.testing.assert_allclose(from_frame, from_geometry, atol=1.0)


def test_misses_and_false_positives_follow_their_rates() -> None:
    noise = DetectorNoise(box_noise=0.0, miss_probability=0.3, false_positives_per_frame=0.5)
    world = _world(noise)
    visible = world.visible_objects(world.render())
    detector = GroundTruthDetector(noise, 640, 480, ["cup", "book"], np.random.default_rng(7))
    frames = 2000
    true_positives = false_positives = 0
    for _ in range(frames):
        detections = detector.detect(world.objects, visible)
        true_positives += sum(d.score > 0.6 for d in detections)  # true ones score 0.55 + 0.4 * fraction
        false_positives += sum(d.score <= 0.6 for d in detections)
        assert all(d.class_name in ("cup", "book") for d in detections)
    assert true_positives / (frames * len(visible)) == pytest.approx(0.7, abs=0.03)
    assert false_positives / frames == pytest.approx(0.5, abs=0.05)


def test_box_noise_has_its_standard_deviation() -> None:
    world = _world(objects=[mug("a", 3.0, 2.0)])
    visible = world.visible_objects(world.render())
    detector = GroundTruthDetector(DetectorNoise(box_noise=3.0, miss_probability=0.0, false_positives_per_frame=0.0),
                                   640, 480, ["cup"], np.random.default_rng(1))
    offsets = [np.subtract(detector.detect(world.objects, visible)[0].box.corners, visible[0].box.corners)
               for _ in range(1000)]
    assert np.std(offsets) == pytest.approx(3.0, rel=0.08)


def test_the_same_seed_gives_the_same_detections() -> None:
    noise = DetectorNoise(box_noise=2.0, miss_probability=0.2, false_positives_per_frame=0.3)
    runs = []
    for seed in (5, 5, 6):
        world = _world(noise, seed=seed)
        runs.append([[(d.class_name, d.box.corners) for d in world.detect()] for _ in range(20)])
    assert runs[0] == runs[1] and runs[0] != runs[2]


def test_hidden_or_mostly_cut_off_objects_are_not_detected() -> None:
    # "cut_off" stands at the left edge of the image, most of it outside.
    world = _world(objects=[mug("front", 3.0, 2.0, size=(0.3, 0.6, 1.3)), mug("behind", 4.0, 2.0),
                            mug("cut_off", 3.3, 3.45)])
    frame = world.render()
    fractions = {world.objects[s.index].id: s.fraction for s in world.visible_objects(frame)}
    assert "behind" not in fractions and 0.0 < fractions["cut_off"] < 0.3
    assert len(world.detect(frame)) == 1


def test_a_segmenting_detector_gives_each_object_its_visible_silhouette() -> None:
    world = World(room_world(objects=[mug("a", 3.5, 1.6), mug("b", 3.0, 2.5, size=(0.2, 0.2, 0.4))],
                             size=(5.0, 4.0)), detector_noise=EXACT, segment=True)
    frame = world.render()
    detections = world.detect(frame)
    assert len(detections) == 2
    for detection in detections:
        assert detection.mask is not None and detection.mask.shape == frame.instance.shape
        ids = np.unique(frame.instance[detection.mask])
        assert len(ids) == 1 and ids[0] >= 0  # one object's pixels, nothing else
        rows, columns = np.nonzero(detection.mask)
        x_min, y_min, x_max, y_max = detection.box.corners
        assert x_min <= columns.min() and columns.max() < x_max and y_min <= rows.min() and rows.max() < y_max
    assert all(d.mask is None for d in _world().detect(frame))  # a plain detector gives boxes only
