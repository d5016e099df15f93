"""The MOTFront adapter on a tiny data set in the layout it assumes, written by the test.

``train/seq_a``: three frames, two look-alike chairs (ids 7, 8) and a table (id 9, rotated 45
degrees about z) that appears in the second frame, plus a detection too small to crop;
``val/seq_b``: two frames without a ``categories`` list (names come from 3D_front_mapping.csv,
or are ``category_<id>``), one box running off the image. Every 2D box is painted in its
object's colour in a lossless PNG, so a crop cut at the wrong place shows it.
"""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path

import cv2
import numpy as np
import pytest

from merlin2_sailor.errors import DependencyError, InvalidInputError
from merlin2_sailor.training.external_source import ALL
from merlin2_sailor.training.motfront_source import MotFrontConfig, MotFrontSource
from merlin2_sailor.training.pair_dataset import PairChunk, PairDatasetConfig, iter_pair_chunks
from merlin2_sailor.training.source_registry import open_source

WIDTH, HEIGHT = 320, 240

# sequence -> frames; a frame: (id, category, centre, extent (x, y, z) before yaw, yaw, bbox, colour)
SEQUENCES = {
    "train/seq_a": [
        [(7, 1, (1.0, 2.0, 0.45), (0.5, 0.5, 0.9), 0.0, (20, 30, 40, 60), (200, 30, 30)),
         (8, 1, (1.8, 2.0, 0.45), (0.5, 0.5, 0.9), 0.0, (90, 30, 40, 60), (30, 200, 30)),
         (11, 1, (3.0, 2.0, 0.45), (0.5, 0.5, 0.9), 0.0, (300, 10, 3, 3), (90, 90, 90))],
        [(7, 1, (1.0, 2.0, 0.45), (0.5, 0.5, 0.9), 0.0, (30, 30, 40, 60), (200, 30, 30)),
         (8, 1, (1.8, 2.0, 0.45), (0.5, 0.5, 0.9), 0.0, (100, 30, 40, 60), (30, 200, 30)),
         (9, 2, (2.0, 4.0, 0.4), (1.0, 1.0, 0.8), math.pi / 4, (160, 100, 80, 50), (30, 30, 200))],
        [(7, 1, (1.0, 2.0, 0.45), (0.5, 0.5, 0.9), 0.0, (40, 32, 40, 60), (200, 30, 30)),
         (8, 1, (1.8, 2.0, 0.45), (0.5, 0.5, 0.9), 0.0, (110, 32, 40, 60), (30, 200, 30)),
         (9, 2, (2.0, 4.0, 0.4), (1.0, 1.0, 0.8), math.pi / 4, (170, 100, 80, 50), (30, 30, 200))],
    ],
    "val/seq_b": [
        [(1, 4, (5.0, 5.0, 0.3), (2.0, 1.6, 0.6), 0.0, (50, 120, 100, 60), (220, 220, 30))],
        [(1, 4, (5.0, 5.0, 0.3), (2.0, 1.6, 0.6), 0.0, (60, 120, 100, 60), (220, 220, 30)),
         (2, 99, (6.0, 3.0, 0.5), (0.4, 0.4, 1.0), 0.0, (280, 150, 70, 40), (30, 220, 220))],
    ],
}


def corners(centre, extent, yaw) -> np.ndarray:
    local = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]) * extent
    c, s = math.cos(yaw), math.sin(yaw)
    return local @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]).T + np.asarray(centre)


def write_motfront(root: Path, sequences=SEQUENCES, with_categories=("train/seq_a",)) -> None:
    (root / "3D_front_mapping.csv").parent.mkdir(parents=True, exist_ok=True)
    (root / "3D_front_mapping.csv").write_text("id,name\n1,chair\n2,table\n4,bed\n")
    for name, frames in sequences.items():
        folder = root / name / "coco_data"
        folder.mkdir(parents=True)
        images, annotations = [], []
        for number, objects in enumerate(frames):
            image = np.zeros((HEIGHT, WIDTH, 3), dtype=np.uint8)
            # Images listed out of order: the frame order is the image id's.
            images.insert(0, {"id": number, "file_name": f"rgb_{number:04d}.png", "width": WIDTH, "height": HEIGHT})
            for identity, category, centre, extent, yaw, bbox, colour in objects:
                x, y, w, h = bbox
                image[y : y + h, x : x + w] = colour
                annotations.append({"id": identity, "image_id": number, "category_id": category, "bbox": list(bbox),
                                    "3Dbbox": corners(centre, extent, yaw).tolist(), "3Dloc": list(centre),
                                    "3Drot": np.eye(3).tolist(), "3Dscale": [1, 1, 1], "jid": "model",
                                    "segmentation": []})
            cv2.imwrite(str(folder / f"rgb_{number:04d}.png"), cv2.cvtColor(image, cv2.COLOR_RGB2BGR))
            (root / name / f"{number}.hdf5").write_bytes(b"")  # depth and pose: present, never read
        content = {"images": images, "annotations": annotations}
        if name in with_categories:
            content["categories"] = [{"id": 1, "name": "chair"}, {"id": 2, "name": "table"}]
        (folder / "coco_annotations.json").write_text(json.dumps(content))


@pytest.fixture
def motfront(tmp_path) -> Path:
    write_motfront(tmp_path / "motfront")
    return tmp_path / "motfront"


def scene(source: MotFrontSource, name: str):
    return next(s for s in source.scenes(ALL, 10) if s.scene_id == f"motfront/{name}")


def test_the_set_s_own_split_folders_are_kept(motfront) -> None:
    source = open_source(f"motfront:{motfront}")
    assert isinstance(source, MotFrontSource)
    assert source.scene_names("train") == ("train/seq_a",)
    assert source.scene_names("validation") == ("val/seq_b",)
    assert source.scene_names("test") == ()


def test_frames_are_samples_and_visible_objects_observations(motfront) -> None:
    source = MotFrontSource(MotFrontConfig(root=str(motfront), frame_interval=0.5))
    a, b = scene(source, "train/seq_a"), scene(source, "val/seq_b")
    assert [len(s.observations) for s in a.samples] == [2, 3, 3]  # the 3 x 3 px detection is dropped
    assert [len(s.observations) for s in b.samples] == [1, 2]
    assert [s.stamp for s in a.samples] == [0.0, 0.5, 1.0]
    assert all(o.stamp == s.stamp for s in a.samples for o in s.observations)
    ids = [[o.instance for o in s.observations] for s in a.samples]
    assert ids == [[0, 1], [0, 1, 2], [0, 1, 2]]  # ids 7, 8, 9 numbered in order of first sight
    assert [o.class_name for o in a.samples[1].observations] == ["chair", "chair", "table"]
    assert [o.class_name for o in b.samples[1].observations] == ["bed", "category_99"]


def test_positions_are_box_centres_and_sizes_axis_aligned_extents(motfront) -> None:
    source = MotFrontSource(MotFrontConfig(root=str(motfront)))
    chair, _, table = scene(source, "train/seq_a").samples[1].observations
    np.testing.assert_allclose(chair.position, (1.0, 2.0, 0.45))
    np.testing.assert_allclose(chair.size, (0.5, 0.5, 0.9))
    np.testing.assert_allclose(table.position, (2.0, 4.0, 0.4), atol=1e-12)
    np.testing.assert_allclose(table.size, (math.sqrt(2), math.sqrt(2), 0.8))  # 1 x 1 m turned 45 degrees
    assert math.isnan(table.depth)


def test_crops_are_the_2d_boxes_clipped_to_the_image(motfront) -> None:
    source = MotFrontSource(MotFrontConfig(root=str(motfront)))
    for name, frames in SEQUENCES.items():
        for sample, objects in zip(scene(source, name).samples, frames, strict=True):
            kept = [o for o in objects if o[5][2] >= 8 and o[5][3] >= 8]
            for observation, (_, _, _, _, _, (x, y, w, h), colour) in zip(sample.observations, kept, strict=True):
                assert observation.box == (x, y, min(x + w, WIDTH), min(y + h, HEIGHT))
                crop = source.render(observation)
                assert crop.shape == (min(h, HEIGHT - y), min(w, WIDTH - x), 3)
                assert np.all(crop == colour)


def test_pairs_follow_algorithm_3(motfront) -> None:
    source = MotFrontSource(MotFrontConfig(root=str(motfront)))
    algorithm_3 = PairDatasetConfig(search_pairs_per_positive=0.0, replaced_pairs_per_revisit=0.0)  # the paper's only
    pairs = PairChunk.concatenate(list(iter_pair_chunks(source.scenes(ALL, 10), algorithm_3)))
    # seq_a: 2, 3, 3 objects -> 0 + 3x2 + 3x3 = 15 pairs, 2 + 3 = 5 positives; seq_b: 0 + 2x1 = 2, 1.
    counts = {s: (int((pairs.scene_ids == s).sum()), int(pairs.labels[pairs.scene_ids == s].sum()))
              for s in ("motfront/train/seq_a", "motfront/val/seq_b")}
    assert counts == {"motfront/train/seq_a": (15, 5), "motfront/val/seq_b": (2, 1)}
    chairs = (pairs.percept_classes == "chair") & (pairs.anchor_classes == "chair") & ~pairs.labels
    assert chairs.sum() == 4 and np.all(pairs.look_alike[chairs])  # the two chairs, 0.8 m apart


def test_a_root_without_split_folders_is_split_by_sequence(tmp_path) -> None:
    sequences = {f"seq_{i}": SEQUENCES["val/seq_b"] for i in range(4)}
    write_motfront(tmp_path / "flat", sequences, with_categories=())
    source = MotFrontSource(MotFrontConfig(root=str(tmp_path / "flat")))
    sizes = [source.split_size(s) for s in ("train", "validation", "test")]
    assert sizes == [2, 1, 1]
    assert sorted(source.scene_names(ALL)) == sorted(sequences)


def test_missing_or_malformed_data_is_one_clear_error(motfront, tmp_path) -> None:
    with pytest.raises(DependencyError, match="MOTFront root .* not found"):
        MotFrontSource(MotFrontConfig(root=str(tmp_path / "nowhere")))
    (tmp_path / "empty").mkdir()
    with pytest.raises(DependencyError, match="holds no sequence"):
        MotFrontSource(MotFrontConfig(root=str(tmp_path / "empty")))
    path = motfront / "val" / "seq_b" / "coco_data" / "coco_annotations.json"
    content = json.loads(path.read_text())
    del content["annotations"][0]["3Dbbox"]
    path.write_text(json.dumps(content))
    source = MotFrontSource(MotFrontConfig(root=str(motfront)))
    with pytest.raises(InvalidInputError, match="lacks bbox, 3Dbbox"):
        list(source.scenes("validation", 1))


def test_identities_that_never_repeat_are_flagged(motfront) -> None:
    path = motfront / "train" / "seq_a" / "coco_data" / "coco_annotations.json"
    content = json.loads(path.read_text())
    for number, annotation in enumerate(content["annotations"]):
        annotation["unique"] = number
    path.write_text(json.dumps(content))
    source = MotFrontSource(MotFrontConfig(root=str(motfront), identity_key="unique"))
    with pytest.warns(UserWarning, match="no object is seen in two frames"):
        list(source.scenes("train", 1))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        list(MotFrontSource(MotFrontConfig(root=str(motfront))).scenes("train", 1))
