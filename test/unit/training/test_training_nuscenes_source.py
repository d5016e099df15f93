"""The nuScenes adapter on a tiny data set in nuScenes' table format, written by the test.

Two scenes of three key frames each: scene A drives along +x past a car and a pedestrian (a
barrier behind the car is never in view); scene B, rotated 90 degrees, passes two look-alike
cars and a truck that appears in the second key frame. Each image is black with every visible
box painted in its instance's colour where the test's own projection (plain matrix maths,
written independently of the adapter) puts it, so a crop cut at the wrong place shows it.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import cv2
import numpy as np
import pytest

from merlin2_sailor.errors import ConfigurationError, DependencyError
from merlin2_sailor.training.external_source import ALL, ImageObservation
from merlin2_sailor.training.nuscenes_source import NuScenesConfig, NuScenesSource, short_class
from merlin2_sailor.training.pair_dataset import PairChunk, PairDatasetConfig, iter_pair_chunks
from merlin2_sailor.training.source_registry import open_source

VERSION = "v1.0-mini"
WIDTH, HEIGHT, FOCAL = 400, 300, 300.0
K = np.array([[FOCAL, 0.0, WIDTH / 2], [0.0, FOCAL, HEIGHT / 2], [0.0, 0.0, 1.0]])
CAMERA_IN_EGO = np.array([1.5, 0.0, 1.5])
# Columns: the camera's x (right), y (down), z (forward) in the ego frame (x forward, y left, z up).
CAMERA_ROTATION = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
START = 1_532_402_927_647_951  # microseconds


def yaw_matrix(yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def quaternion_wxyz(matrix: np.ndarray) -> list[float]:
    w = math.sqrt(max(1.0 + np.trace(matrix), 0.0)) / 2.0
    if w > 1e-6:
        return [w, (matrix[2, 1] - matrix[1, 2]) / (4 * w), (matrix[0, 2] - matrix[2, 0]) / (4 * w),
                (matrix[1, 0] - matrix[0, 1]) / (4 * w)]
    raise AssertionError("the fixture only uses rotations away from 180 degrees")


# scene name -> (ego yaw, ego start, ego step per sample, objects); an object: instance,
# category, centre, size (w, l, h), yaw, the samples it is annotated in, colour (RGB).
SCENES = {
    "scene-0001": (0.0, (0.0, 0.0), (2.0, 0.0), [
        ("a-car", "vehicle.car", (20.0, -2.0, 1.0), (2.0, 4.0, 1.5), 0.0, (0, 1, 2), (230, 40, 40)),
        ("a-walker", "human.pedestrian.adult", (12.0, 3.0, 0.9), (0.8, 0.8, 1.8), 0.0, (0, 1, 2), (40, 230, 40)),
        ("a-barrier", "movable_object.barrier", (-10.0, 0.0, 0.5), (2.0, 0.5, 1.0), 0.0, (0, 1, 2), (40, 40, 230)),
    ]),
    "scene-0002": (math.pi / 2, (100.0, 0.0), (0.0, 2.0), [
        ("b-car-1", "vehicle.car", (98.0, 20.0, 1.0), (2.0, 4.0, 1.5), math.pi / 2, (0, 1, 2), (230, 230, 40)),
        ("b-car-2", "vehicle.car", (104.0, 24.0, 1.0), (2.0, 4.0, 1.5), math.pi / 2, (0, 1, 2), (230, 40, 230)),
        ("b-truck", "vehicle.truck", (100.5, 30.0, 1.5), (2.5, 8.0, 3.0), math.pi / 2, (1, 2), (40, 230, 230)),
    ]),
}


def project(centre, size, yaw, ego_rotation, ego_translation) -> np.ndarray | None:
    """The test's own projection: the box's (x0, y0, x1, y1) in the image, None when behind."""
    width, length, height = size
    local = np.array([[x * length / 2, y * width / 2, z * height / 2]
                      for x in (1, -1) for y in (1, -1) for z in (1, -1)])
    world = local @ yaw_matrix(yaw).T + np.asarray(centre)
    ego = (world - ego_translation) @ ego_rotation  # R^T (p - t), row-wise
    camera = (ego - CAMERA_IN_EGO) @ CAMERA_ROTATION
    if np.any(camera[:, 2] < 0.1):
        return None
    pixels = camera @ K.T
    pixels = pixels[:, :2] / pixels[:, 2:3]
    x0, y0 = np.floor(pixels.min(axis=0)).clip(0, None)
    x1, y1 = np.ceil(pixels.max(axis=0)).clip(None, (WIDTH, HEIGHT))
    return np.array([x0, y0, x1, y1])


def write_nuscenes(root: Path) -> dict[str, dict]:
    """Write the fixture; return, per annotation token, what the adapter should make of it."""
    tables: dict[str, list] = {name: [] for name in (
        "scene", "sample", "sample_data", "sample_annotation", "instance", "category", "ego_pose",
        "calibrated_sensor", "sensor", "log", "visibility", "attribute", "map")}
    tables["sensor"] = [{"token": "sensor-cam", "channel": "CAM_FRONT", "modality": "camera"},
                        {"token": "sensor-lidar", "channel": "LIDAR_TOP", "modality": "lidar"}]
    tables["calibrated_sensor"] = [
        {"token": "calib-cam", "sensor_token": "sensor-cam", "translation": CAMERA_IN_EGO.tolist(),
         "rotation": quaternion_wxyz(CAMERA_ROTATION), "camera_intrinsic": K.tolist()},
        {"token": "calib-lidar", "sensor_token": "sensor-lidar", "translation": [0.9, 0.0, 1.8],
         "rotation": [1.0, 0.0, 0.0, 0.0], "camera_intrinsic": []},
    ]
    (root / "samples" / "CAM_FRONT").mkdir(parents=True)
    expected: dict[str, dict] = {}
    categories: dict[str, str] = {}
    clock = START
    for scene_number, (scene_name, (yaw, start, step, objects)) in enumerate(SCENES.items()):
        scene_token = f"scene-token-{scene_number}"
        tables["scene"].append({"token": scene_token, "name": scene_name, "log_token": "log",
                                "nbr_samples": 3, "description": "fixture"})
        for instance, category, *_ in objects:
            category_token = categories.setdefault(category, f"category-{len(categories)}")
            tables["instance"].append({"token": instance, "category_token": category_token})
        for k in range(3):
            clock += 500_000
            sample_token = f"sample-{scene_number}-{k}"
            tables["sample"].append({"token": sample_token, "timestamp": clock, "scene_token": scene_token,
                                     "prev": "", "next": ""})
            ego_rotation = yaw_matrix(yaw)
            ego_translation = np.array([start[0] + k * step[0], start[1] + k * step[1], 0.0])
            tables["ego_pose"].append({"token": f"ego-{sample_token}", "timestamp": clock,
                                       "rotation": quaternion_wxyz(ego_rotation),
                                       "translation": ego_translation.tolist()})
            filename = f"samples/CAM_FRONT/{sample_token}.jpg"
            tables["sample_data"] += [
                {"token": f"cam-{sample_token}", "sample_token": sample_token, "ego_pose_token": f"ego-{sample_token}",
                 "calibrated_sensor_token": "calib-cam", "timestamp": clock, "fileformat": "jpg",
                 "is_key_frame": True, "height": HEIGHT, "width": WIDTH, "filename": filename},
                {"token": f"sweep-{sample_token}", "sample_token": sample_token,
                 "ego_pose_token": f"ego-{sample_token}",
                 "calibrated_sensor_token": "calib-cam", "timestamp": clock + 80_000, "fileformat": "jpg",
                 "is_key_frame": False, "height": HEIGHT, "width": WIDTH, "filename": "sweeps/none.jpg"},
                {"token": f"lidar-{sample_token}", "sample_token": sample_token,
                 "ego_pose_token": f"ego-{sample_token}",
                 "calibrated_sensor_token": "calib-lidar", "timestamp": clock, "fileformat": "pcd",
                 "is_key_frame": True, "height": 0, "width": 0, "filename": "samples/LIDAR_TOP/none.pcd.bin"},
            ]
            image = np.zeros((HEIGHT, WIDTH, 3), dtype=np.uint8)
            visible = []
            for instance, category, centre, size, object_yaw, annotated, colour in objects:
                if k not in annotated:
                    continue
                token = f"ann-{instance}-{k}"
                tables["sample_annotation"].append({
                    "token": token, "sample_token": sample_token, "instance_token": instance,
                    "visibility_token": "4", "attribute_tokens": [], "translation": list(centre),
                    "size": list(size), "rotation": quaternion_wxyz(yaw_matrix(object_yaw)),
                    "prev": "", "next": "", "num_lidar_pts": 10, "num_radar_pts": 0})
                box = project(centre, size, object_yaw, ego_rotation, ego_translation)
                if box is not None:
                    depth = float(np.linalg.norm(np.asarray(centre) - ego_translation))
                    visible.append((depth, box, colour))
                    expected[token] = dict(scene=scene_name, sample=k, instance=instance, box=box, colour=colour,
                                           position=centre, size=size, stamp=clock * 1e-6, category=category)
            for _, box, colour in sorted(visible, key=lambda v: -v[0]):  # far first: near ones occlude
                x0, y0, x1, y1 = box.astype(int)
                image[y0:y1, x0:x1] = colour
            cv2.imwrite(str(root / filename), cv2.cvtColor(image, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, 95])
    tables["category"] = [{"token": token, "name": name, "description": ""} for name, token in categories.items()]
    (root / VERSION).mkdir()
    for name, records in tables.items():
        (root / VERSION / f"{name}.json").write_text(json.dumps(records))
    return expected


@pytest.fixture
def nuscenes(tmp_path) -> tuple[Path, dict[str, dict]]:
    root = tmp_path / "nuscenes"
    root.mkdir()
    return root, write_nuscenes(root)


def all_observations(source: NuScenesSource) -> dict[str, ImageObservation]:
    return {o.crop_id.split("/", 1)[1]: o for scene in source.scenes(ALL, 10) for o in scene.observations}


def test_scenes_samples_and_observations_are_the_visible_annotations(nuscenes) -> None:
    root, expected = nuscenes
    source = NuScenesSource(NuScenesConfig(dataroot=str(root)))  # the only version found
    assert source.version == VERSION
    scenes = list(source.scenes(ALL, 10))
    assert sorted(s.scene_id for s in scenes) == ["nuscenes/scene-0001", "nuscenes/scene-0002"]
    assert all(len(s.samples) == 3 for s in scenes)  # the sweep and the lidar are not samples
    counts = {s.scene_id: [len(sample.observations) for sample in s.samples] for s in scenes}
    assert counts == {"nuscenes/scene-0001": [2, 2, 2], "nuscenes/scene-0002": [2, 3, 3]}  # barrier: behind
    assert set(all_observations(source)) == set(expected)


def test_identities_classes_positions_sizes_and_stamps(nuscenes) -> None:
    root, expected = nuscenes
    observations = all_observations(NuScenesSource(NuScenesConfig(dataroot=str(root), version=VERSION)))
    identity: dict[tuple[str, str], int] = {}
    for token, truth in expected.items():
        o = observations[token]
        assert identity.setdefault((truth["scene"], truth["instance"]), o.instance) == o.instance
        assert o.class_name == short_class(truth["category"])
        np.testing.assert_allclose(o.position, truth["position"])
        np.testing.assert_allclose(o.size, truth["size"])
        assert o.stamp == pytest.approx(truth["stamp"], abs=1e-6) and o.sample == truth["sample"]
    for scene in ("scene-0001", "scene-0002"):  # distinct instances, distinct ids
        ids = [i for (s, _), i in identity.items() if s == scene]
        assert len(set(ids)) == len(ids)
    classes = {o.class_name for o in observations.values()}
    assert classes == {"car", "pedestrian", "truck"}


def test_crops_are_cut_where_the_boxes_project(nuscenes) -> None:
    root, expected = nuscenes
    source = NuScenesSource(NuScenesConfig(dataroot=str(root)))
    for token, o in all_observations(source).items():
        truth = expected[token]
        np.testing.assert_allclose(o.box, truth["box"], atol=1)
        crop = source.render(o)
        assert crop.dtype == np.uint8 and crop.shape == (o.box[3] - o.box[1], o.box[2] - o.box[0], 3)
        h, w = crop.shape[:2]
        centre = crop[h // 4 : 3 * h // 4 + 1, w // 4 : 3 * w // 4 + 1].reshape(-1, 3)
        np.testing.assert_allclose(np.median(centre, axis=0), truth["colour"], atol=12)
        assert o.view.pixels == (w, h) and o.depth > 0.0


def test_pairs_follow_algorithm_3(nuscenes) -> None:
    root, _ = nuscenes
    source = NuScenesSource(NuScenesConfig(dataroot=str(root)))
    algorithm_3 = PairDatasetConfig(search_pairs_per_positive=0.0, replaced_pairs_per_revisit=0.0)  # the paper's only
    pairs = PairChunk.concatenate(list(iter_pair_chunks(source.scenes(ALL, 10), algorithm_3)))
    # Scene A: 2 objects in each of 3 samples -> 0 + 2x2 + 2x2 = 8 pairs, 4 positives.
    # Scene B: 2, 3, 3 objects (the truck joins) -> 0 + 3x2 + 3x3 = 15 pairs, 5 positives.
    by_scene = {s: (int((pairs.scene_ids == s).sum()), int(pairs.labels[pairs.scene_ids == s].sum()))
                for s in ("nuscenes/scene-0001", "nuscenes/scene-0002")}
    assert by_scene == {"nuscenes/scene-0001": (8, 4), "nuscenes/scene-0002": (15, 5)}
    assert np.all(pairs.percept_stamps > pairs.anchor_last_seen)
    positives = pairs.labels
    assert np.all(pairs.percept_classes[positives] == pairs.anchor_classes[positives])


def test_scenes_are_split_by_scene(nuscenes) -> None:
    root, _ = nuscenes
    source = open_source(f"nuscenes:{root}:{VERSION}")
    assert isinstance(source, NuScenesSource)
    assert (source.split_size("train"), source.split_size("validation"), source.split_size("test")) == (1, 1, 0)
    assert set(source.scene_names("train")) | set(source.scene_names("validation")) == set(SCENES)
    assert list(source.scenes("test", 5)) == []


def test_visibility_and_crop_size_thresholds_drop_annotations(nuscenes) -> None:
    root, expected = nuscenes
    assert not all_observations(NuScenesSource(NuScenesConfig(dataroot=str(root), min_crop_pixels=1000)))
    assert len(all_observations(NuScenesSource(NuScenesConfig(dataroot=str(root), min_visibility=4)))) == len(expected)


def test_missing_data_is_one_clear_error(nuscenes, tmp_path) -> None:
    root, _ = nuscenes
    with pytest.raises(DependencyError, match="dataroot .* not found"):
        NuScenesSource(NuScenesConfig(dataroot=str(tmp_path / "nowhere")))
    (root / "v1.0-test").mkdir()
    (root / "v1.0-test" / "scene.json").write_text("[]")
    with pytest.raises(ConfigurationError, match="found v1.0-mini, v1.0-test"):
        NuScenesSource(NuScenesConfig(dataroot=str(root)))
    with pytest.raises(DependencyError, match="lacks scene.json, sample.json"):
        NuScenesSource(NuScenesConfig(dataroot=str(root), version="v1.0-absent"))
    with pytest.raises(ConfigurationError, match="no camera 'CAM_BACK'"):
        NuScenesSource(NuScenesConfig(dataroot=str(root), version=VERSION, camera="CAM_BACK"))
    with pytest.raises(ConfigurationError, match="Unknown data source"):
        open_source("kitti:/data")


def test_sailor_train_and_evaluate_run_on_the_fixture(nuscenes, tmp_path, capsys) -> None:
    pytest.importorskip("torch", reason="pip install torch==2.13.0 (CPU build)")
    from merlin2_sailor.cli.main import main

    root, _ = nuscenes
    weights = tmp_path / "net.pt"
    common = ["--source", f"nuscenes:{root}:{VERSION}", "--no-cache"]
    assert main(["train", *common, "--epochs", "1", "--batch-size", "8", "--output", str(weights),
                 "--device", "cpu"]) == 0
    assert weights.is_file() and (tmp_path / "net_loss.png").is_file()
    provenance = json.loads(weights.with_suffix(".json").read_text())
    assert provenance["source"] == f"nuscenes:{root}:{VERSION}"
    assert provenance["splits"] == {"train": 1, "validation": 1, "test": 0}
    assert main(["evaluate", *common, "--weights", str(weights), "--split", ALL]) == 0
    assert "IDF1" in capsys.readouterr().out
    assert main(["train", "--source", f"nuscenes:{tmp_path / 'nowhere'}"]) == 2
    assert "nuScenes dataroot" in capsys.readouterr().err
