"""ByteTrack adapter: id strings, empty ids, resets, stamps, frame rate, and MOT metrics on TUD-Campus."""

from __future__ import annotations

import numpy as np
import pytest

from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.perception.detection import Detection

tracker_module = pytest.importorskip("merlin2_sailor.perception.tracker")
ByteTrackAdapter, ByteTrackConfig = tracker_module.ByteTrackAdapter, tracker_module.ByteTrackConfig


def person(x: float, score: float = 0.9, y: float = 100.0) -> Detection:
    return Detection(1, "person", score, BoundingBox2D.from_corners(x, y, x + 60.0, y + 150.0))


def test_a_moving_object_keeps_one_string_id_after_confirmation() -> None:
    tracker = ByteTrackAdapter(ByteTrackConfig(frame_rate=30.0))
    ids = [tracker.update([person(100.0 + 3.0 * frame)])[0].tracker_id for frame in range(10)]
    assert ids[0] == ""  # one frame is not yet a track (minimum_consecutive_frames = 2)
    assert len(set(ids[1:])) == 1 and ids[1] != "" and isinstance(ids[1], str)


def test_two_objects_get_distinct_ids_in_input_order() -> None:
    tracker = ByteTrackAdapter()
    for frame in range(3):
        left, right = tracker.update([person(500.0 - frame), person(50.0 + frame)])
    assert left.tracker_id and right.tracker_id and left.tracker_id != right.tracker_id
    assert left.box.center_x > right.box.center_x  # outputs follow the input order


def test_low_scores_get_no_id_and_start_no_track() -> None:
    tracker = ByteTrackAdapter(ByteTrackConfig(low_confidence_threshold=0.1, new_track_threshold=0.6))
    for _ in range(5):
        (weak,) = tracker.update([person(100.0, score=0.05)])
        (doubtful,) = tracker.update([person(300.0, score=0.4)])
    assert weak.tracker_id == "" and doubtful.tracker_id == ""


def test_low_score_detection_extends_an_existing_track() -> None:
    tracker = ByteTrackAdapter()
    for frame in range(4):
        (confident,) = tracker.update([person(100.0 + frame, score=0.9)])
    (weak,) = tracker.update([person(104.0, score=0.3)])  # ByteTrack's second association
    assert weak.tracker_id == confident.tracker_id != ""


def test_ids_are_never_reused_after_reset_and_carry_the_prefix() -> None:
    tracker = ByteTrackAdapter(ByteTrackConfig(id_prefix="front_"))
    for _ in range(3):
        (before,) = tracker.update([person(100.0)])
    tracker.reset()
    for _ in range(3):
        (after,) = tracker.update([person(100.0)])
    assert before.tracker_id.startswith("front_") and after.tracker_id.startswith("front_")
    assert before.tracker_id != after.tracker_id


def test_stale_stamps_leave_the_tracks_alone() -> None:
    tracker = ByteTrackAdapter()
    for frame in range(4):
        (tracked,) = tracker.update([person(100.0)], stamp=10.0 + frame / 30.0)
    (duplicate,) = tracker.update([person(400.0)], stamp=10.0 + 3 / 30.0)
    (old,) = tracker.update([person(400.0)], stamp=9.0)
    assert duplicate.tracker_id == "" and old.tracker_id == ""
    (again,) = tracker.update([person(101.0)], stamp=10.0 + 4 / 30.0)
    assert again.tracker_id == tracked.tracker_id


def test_empty_frames_are_fine() -> None:
    tracker = ByteTrackAdapter()
    assert tracker.update([]) == []
    (first,) = tracker.update([person(10.0)])
    assert tracker.update([]) == []
    assert first.tracker_id == ""


@pytest.mark.parametrize(("frame_rate", "same_id"), [(30.0, True), (10.0, False)])
def test_lost_track_buffer_follows_the_camera_frame_rate(frame_rate: float, same_id: bool) -> None:
    """30 frames at 30 fps is one second; at 10 fps the same second is 10 frames.

    The person vanishes for 20 frames: within the buffer at 30 fps, beyond it at 10 fps.
    """
    tracker = ByteTrackAdapter(ByteTrackConfig(frame_rate=frame_rate, lost_track_buffer=30))
    for _ in range(5):
        (seen,) = tracker.update([person(100.0)])
    for _ in range(20):
        tracker.update([])
    for _ in range(2):
        (back,) = tracker.update([person(100.0)])
    assert (back.tracker_id == seen.tracker_id) is same_id


@pytest.mark.parametrize(
    "arguments",
    [
        dict(frame_rate=0.0),
        dict(frame_rate=float("nan")),
        dict(low_confidence_threshold=0.7, high_confidence_threshold=0.5),
        dict(minimum_match_overlap=0.0),
        dict(lost_track_buffer=-1),
        dict(minimum_consecutive_frames=0),
    ],
)
def test_invalid_config_is_rejected(arguments: dict) -> None:
    with pytest.raises(ConfigurationError):
        ByteTrackConfig(**arguments)


# --- MOT metrics on real trajectories ----------------------------------------------------------
# TUD-Campus (71 frames at 25 fps, 8 people crossing, 359 boxes) with a simulated detector:
# boxes jittered by 2 % of their size, 10 % missed, one false positive per frame on average
# scored below the new-track threshold (as a decent detector's clutter is). True detections
# score between 0.5 and 1. Measured with this protocol and the paper's ByteTrack defaults, over
# five seeds: MOTA 0.836-0.877 (mean 0.862), IDF1 0.814-0.935 (mean 0.899).
#
# MOTA >= 0.88 cannot be reached with this protocol: a tracker reports only detected boxes, so
# the 10 % missed detections (~36) are misses, and each of the 8 tracks costs at least one more
# before it is confirmed. That bounds MOTA at about 1 - 44/359 = 0.877 before any false positive
# or switch (computed per seed, the bound averages 0.874). The thresholds sit under the measured
# means, and the test also checks the bound holds and that the tracker comes within 0.03 of it.
TUD_CAMPUS_FRAME_RATE = 25.0
MOT_SEEDS = range(5)
MINIMUM_MEAN_MOTA = 0.85
MINIMUM_MEAN_IDF1 = 0.88


def simulate_detector(ground_truth: np.ndarray, rng: np.random.Generator) -> list[list[Detection]]:
    frames = []
    for frame in np.unique(ground_truth[:, 0]).astype(int):
        detections = []
        for row in ground_truth[ground_truth[:, 0] == frame]:
            if rng.random() < 0.10:
                continue
            x, y, width, height = row[2:6]
            x += rng.normal(0.0, 0.02 * width)
            y += rng.normal(0.0, 0.02 * height)
            width *= 1.0 + rng.normal(0.0, 0.02)
            height *= 1.0 + rng.normal(0.0, 0.02)
            box = BoundingBox2D.from_corners(x, y, x + width, y + height)
            detections.append(Detection(1, "person", float(rng.uniform(0.5, 1.0)), box))
        for _ in range(rng.poisson(1.0)):
            width, height = rng.uniform(30.0, 120.0), rng.uniform(60.0, 250.0)
            x, y = rng.uniform(0.0, 640.0 - width), rng.uniform(0.0, 480.0 - height)
            box = BoundingBox2D.from_corners(x, y, x + width, y + height)
            detections.append(Detection(1, "person", float(rng.uniform(0.1, 0.5)), box))
        frames.append([detections[index] for index in rng.permutation(len(detections))])
    return frames


def test_mot_metrics_on_tud_campus(tud_campus_ground_truth: np.ndarray) -> None:
    motmetrics = pytest.importorskip("motmetrics")
    ground_truth = tud_campus_ground_truth
    frame_numbers = np.unique(ground_truth[:, 0]).astype(int)
    motas, idf1s, bounds = [], [], []
    for seed in MOT_SEEDS:
        rng = np.random.default_rng(seed)
        tracker = ByteTrackAdapter(ByteTrackConfig(frame_rate=TUD_CAMPUS_FRAME_RATE))
        accumulator = motmetrics.MOTAccumulator(auto_id=False)
        simulated = simulate_detector(ground_truth, rng)
        for frame, detections in zip(frame_numbers, simulated, strict=True):
            tracked = [d for d in tracker.update(detections, stamp=frame / TUD_CAMPUS_FRAME_RATE) if d.tracker_id]
            truth = ground_truth[ground_truth[:, 0] == frame]
            hypotheses = np.array([[d.box.corners[0], d.box.corners[1], d.box.width, d.box.height] for d in tracked])
            distances = motmetrics.distances.iou_matrix(truth[:, 2:6], hypotheses.reshape(-1, 4), max_iou=0.5)
            accumulator.update(
                truth[:, 1].astype(int).tolist(), [d.tracker_id for d in tracked], distances, frameid=frame
            )
        summary = motmetrics.metrics.create().compute(accumulator, metrics=["mota", "idf1"], name="tud")
        motas.append(float(summary["mota"].iloc[0]))
        idf1s.append(float(summary["idf1"].iloc[0]))
        true_detections = sum(1 for detections in simulated for d in detections if d.score >= 0.5)
        births = len(np.unique(ground_truth[:, 1]))
        bounds.append((true_detections - births) / len(ground_truth))
    assert np.mean(motas) >= MINIMUM_MEAN_MOTA, motas
    assert np.mean(idf1s) >= MINIMUM_MEAN_IDF1, idf1s
    assert all(mota <= bound + 1e-9 for mota, bound in zip(motas, bounds, strict=True))  # the bound above holds
    assert np.mean(bounds) - np.mean(motas) < 0.03, (bounds, motas)  # and we are close to it
