"""The replay loop on tiny scripted frames: anchors made, identities kept, files written."""

from __future__ import annotations

import json
from collections.abc import Iterator, Sequence

import cv2
import numpy as np
import pytest

from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.perception.detection import Detection
from merlin2_sailor_demos.replay.pipeline import ReplayPipeline, create_replay_tracker
from merlin2_sailor_demos.replay.runner import ReplayOptions, format_summary, run_replay
from merlin2_sailor_demos.replay.source import WORLD_FROM_LEVEL_OPTICAL, ReplayFrame, ReplaySource, frame_indices

WIDTH, HEIGHT = 96, 64
CUP = ("cup", 47, 0.9)
BOOK = ("book", 84, 0.8)


class TinySource(ReplaySource):
    """``count`` 96x64 frames of a still camera: a wall 3 m away, a nearer block 2 m away on the
    left, and a hole without depth in the bottom-right corner."""

    name = "tiny"
    frame_rate = 10.0
    default_frames = 3

    def __init__(self, count: int = 3) -> None:
        self.count = count
        self.intrinsics = CameraIntrinsics(80.0, 80.0, (WIDTH - 1) / 2, (HEIGHT - 1) / 2, WIDTH, HEIGHT)
        depth = np.full((HEIGHT, WIDTH), 3.0, dtype=np.float32)
        depth[10:40, 5:45] = 2.0
        depth[48:, 70:] = np.nan
        self.depth = depth
        rng = np.random.default_rng(0)
        self.color = rng.integers(0, 255, (HEIGHT, WIDTH, 3), dtype=np.uint8)

    @property
    def description(self) -> str:
        return "a tiny scripted scene"

    @property
    def frame_count(self) -> int:
        return self.count

    def frames(self, indices: Sequence[int]) -> Iterator[ReplayFrame]:
        pose = Pose(WORLD_FROM_LEVEL_OPTICAL, np.array([0.0, 0.0, 1.0]))
        for index in indices:
            yield ReplayFrame(index, index / self.frame_rate, self.color, self.depth, self.intrinsics, pose)


class ScriptedDetector:
    """Returns the scripted detections of each call in turn (nothing once the script ends)."""

    def __init__(self, script: Sequence[Sequence[tuple[tuple[str, int, float], tuple[float, ...]]]]) -> None:
        self.script = list(script)
        self.calls = 0

    def detect(self, image_rgb: np.ndarray) -> list[Detection]:
        frame = self.script[self.calls] if self.calls < len(self.script) else []
        self.calls += 1
        return [Detection(class_id, name, score, BoundingBox2D.from_corners(*corners))
                for (name, class_id, score), corners in frame]


def cup_and_book(frames: int) -> list[list]:
    """A cup on the near block drifting one pixel a frame, a book on the wall, both every frame."""
    return [[(CUP, (10 + k, 15, 30 + k, 35)), (BOOK, (55, 10, 75, 30))] for k in range(frames)]


def test_anchors_are_made_once_and_keep_their_symbols_across_frames() -> None:
    source = TinySource(3)
    pipeline = ReplayPipeline(source, ScriptedDetector(cup_and_book(3)), create_replay_tracker(source, 1))
    outcomes = [pipeline.step(frame) for frame in source.frames([0, 1, 2])]
    symbols = [[box.symbol for box in outcome.boxes] for outcome in outcomes]
    assert symbols == [["cup_1", "book_1"]] * 3
    assert [len(outcome.result.acquired) for outcome in outcomes] == [2, 0, 0]
    cup = pipeline.anchoring.get("cup_1")
    assert cup is not None and cup.state.value == "confirmed" and cup.times_seen == 3
    # The cup is on the block 2 m in front of the camera, 1 m high: x forward, y left, z up.
    assert cup.position[0] == pytest.approx(2.0, abs=0.05)
    assert cup.position[1] > 0.0  # left of the optical axis
    # ByteTrack confirms a track on its second frame: ids from then on, the same one each time.
    assert [outcome.boxes[0].detection.tracker_id for outcome in outcomes][1:] == ["0", "0"]


def test_the_pipeline_anchors_into_the_core_it_is_given() -> None:
    from merlin2_sailor.anchoring.anchoring import Anchoring
    from merlin2_sailor.anchoring.symbols import SymbolCounter

    source = TinySource(1)
    anchoring = Anchoring(source.anchoring_settings().core, symbol_factory=SymbolCounter({"cup": 6}))
    pipeline = ReplayPipeline(source, ScriptedDetector(cup_and_book(1)), None, anchoring)
    assert pipeline.anchoring is anchoring  # even while it is empty (and so falsy)
    (outcome,) = [pipeline.step(frame) for frame in source.frames([0])]
    assert [box.symbol for box in outcome.boxes] == ["cup_7", "book_1"] and len(anchoring) == 2


def test_a_source_runs_the_anchoring_nodes_settings_offline_with_what_its_camera_needs(tmp_path) -> None:
    from merlin2_sailor.anchoring.settings import load_anchoring_settings
    from merlin2_sailor.resources import config_file

    deployed = load_anchoring_settings(config_file("anchoring.yaml"))
    settings = TinySource(1).anchoring_settings()
    assert settings.core == deployed.core and settings.matcher == deployed.matcher
    assert (settings.persistence.knowledge_base, settings.persistence.state_folder) == ("", "")
    # A default pipeline runs exactly that.
    assert ReplayPipeline(TinySource(1), ScriptedDetector([]), None).anchoring.config == deployed.core

    class FarSource(TinySource):
        def anchoring_overrides(self):
            return {"visible_range": 30.0, "forget_after": 5.0}

    parameters = tmp_path / "robot.yaml"
    parameters.write_text("anchoring:\n  ros__parameters: {visible_range: 4.0, confirm_after: 5, forget_after: 9.0}\n")
    settings = FarSource(1).anchoring_settings(parameters, overrides={"forget_after": 7.0})
    # The file's values, then the source's camera, then the caller's.
    assert settings.core.lifecycle.confirm_after == 5
    assert settings.core.visibility.frustum.far == 30.0
    assert settings.core.lifecycle.forget_after == 7.0


def test_a_detection_without_depth_is_reported_and_not_anchored() -> None:
    source = TinySource(1)
    script = [[(CUP, (74, 50, 90, 62))]]  # inside the hole without depth
    pipeline = ReplayPipeline(source, ScriptedDetector(script), None)
    (outcome,) = [pipeline.step(frame) for frame in source.frames([0])]
    assert outcome.boxes[0].symbol == ""
    assert outcome.boxes[0].drop_reason == "too_few_depth_pixels"
    assert len(pipeline.anchoring) == 0


def test_the_replay_writes_frames_video_and_an_anchors_summary(tmp_path) -> None:
    source = TinySource(3)
    lines: list[str] = []
    pipeline = ReplayPipeline(source, ScriptedDetector(cup_and_book(3)), create_replay_tracker(source, 1))
    report = run_replay(pipeline, ReplayOptions(tmp_path, image_every=2, header={"detector": "scripted"}),
                        say=lines.append)

    pngs = sorted(path.name for path in (tmp_path / "frames").glob("*.png"))
    assert pngs == ["frame_000000.png", "frame_000002.png"]  # every 2nd, and the last
    image = cv2.imread(str(tmp_path / "frames" / "frame_000002.png"))
    assert image.shape == (HEIGHT, WIDTH, 3)
    videos = [path for path in report.files if path.suffix in (".mp4", ".avi")]
    assert len(videos) == 1 and videos[0].stat().st_size > 0

    saved = json.loads((tmp_path / "anchors.json").read_text())
    assert saved["source"] == "tiny" and saved["detector"] == "scripted"
    assert saved["summary"]["frames"] == 3 and saved["summary"]["anchors"] == 2
    assert saved["summary"]["tracker_ids_split_over_symbols"] == {}
    cup = next(anchor for anchor in saved["anchors"] if anchor["symbol"] == "cup_1")
    assert (cup["times_seen"], cup["frames_seen"], cup["state"]) == (3, 3, "confirmed")
    assert cup["first_frame"] == 0 and cup["last_frame"] == 2 and cup["tracker_ids"] == ["0"]
    table = (tmp_path / "anchors.md").read_text()
    assert "| cup_1 | cup |" in table and "| book_1 | book |" in table

    assert any("acquired cup_1" in line and "acquired book_1" in line for line in lines)
    assert any("confirmed cup_1" in line for line in lines)
    text = format_summary(report)
    assert "anchors 2 (2 confirmed)" in text and "cup_1" in text


def test_an_object_no_longer_seen_where_it_should_be_turns_missing(tmp_path) -> None:
    source = TinySource(7)
    script = cup_and_book(3) + [[(BOOK, (55, 10, 75, 30))]] * 4  # the cup is gone from frame 3 on
    lines: list[str] = []
    pipeline = ReplayPipeline(source, ScriptedDetector(script), create_replay_tracker(source, 1))
    report = run_replay(pipeline, ReplayOptions(tmp_path, frames=7, video=False), say=lines.append)
    states = {anchor["symbol"]: anchor["state"] for anchor in report.anchors}
    assert states == {"cup_1": "missing", "book_1": "confirmed"}
    assert any(line.startswith("frame    5: missing cup_1") for line in lines)
    assert not list(tmp_path.glob("replay.*"))


def test_a_second_replay_into_the_same_folder_leaves_no_frames_of_the_first(tmp_path) -> None:
    for count, every in ((3, 1), (2, 5)):
        source = TinySource(count)
        pipeline = ReplayPipeline(source, ScriptedDetector(cup_and_book(count)), None)
        run_replay(pipeline, ReplayOptions(tmp_path, image_every=every, video=False), say=lambda _: None)
    assert sorted(path.name for path in (tmp_path / "frames").glob("*.png")) == [
        "frame_000000.png", "frame_000001.png"]


def test_frame_selection_takes_first_stride_and_count_and_refuses_nonsense() -> None:
    assert frame_indices(10, first=2, count=3, stride=3) == [2, 5, 8]
    assert frame_indices(10, first=0, count=None, stride=4) == [0, 4, 8]
    for first, count, stride in ((0, 3, 0), (10, 3, 1), (0, 0, 1), (-1, 3, 1)):
        with pytest.raises(ConfigurationError):
            frame_indices(10, first, count, stride)
