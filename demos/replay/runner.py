"""The replay loop: frames through the pipeline, a running account, and the files it writes.

The account is one line per frame in which anchors were acquired, confirmed, went missing, were
found again or forgotten, under a progress bar on a terminal (a progress line every tenth of the
way otherwise).

Into the output folder go ``frames/frame_NNNNNN.png`` (every k-th processed frame and the
last, annotated), ``replay.mp4`` (every processed frame, annotated; MPEG-4 Part 2 through
OpenCV, or Motion-JPEG ``replay.avi`` where that encoder is missing), ``anchors.json`` and
``anchors.md`` (see :mod:`.anchor_log`). Ctrl-C stops the loop early; what was processed is
still written.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from merlin2_sailor.anchoring.events import AnchorEvent, AnchorEventKind
from merlin2_sailor.training.progress import progress_bar
from merlin2_sailor_demos.replay.anchor_log import AnchorLog
from merlin2_sailor_demos.replay.drawing import annotate
from merlin2_sailor_demos.replay.pipeline import ReplayPipeline
from merlin2_sailor_demos.replay.source import frame_indices

#: About this many annotated PNGs when ``image_every`` is not given.
DEFAULT_IMAGE_COUNT = 12
VIDEO_FORMATS = (("mp4v", "replay.mp4"), ("MJPG", "replay.avi"))

_ACCOUNTED = {
    AnchorEventKind.ACQUIRED: "acquired",
    AnchorEventKind.CONFIRMED: "confirmed",
    AnchorEventKind.MISSING: "missing",
    AnchorEventKind.FORGOTTEN: "forgotten",
    AnchorEventKind.RETRACTED: "retracted",
    AnchorEventKind.AMBIGUOUS: "ambiguous",
}


@dataclass(frozen=True, slots=True)
class ReplayOptions:
    """``frames`` (None: the source's default), ``stride``, ``first``: which source frames;
    ``image_every`` (None: about a dozen PNGs); ``video``: write the annotated video;
    ``header``: extra fields for the report (detector, matcher)."""

    output: Path
    frames: int | None = None
    stride: int = 1
    first: int = 0
    image_every: int | None = None
    video: bool = True
    header: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True, slots=True)
class ReplayReport:
    summary: dict[str, Any]
    anchors: list[dict[str, Any]]
    files: list[Path]
    seconds: float
    interrupted: bool


def run_replay(pipeline: ReplayPipeline, options: ReplayOptions, say: Callable[[str], None] = print) -> ReplayReport:
    """Replay the source's frames through ``pipeline``; write the outputs; return the report."""
    source = pipeline.source
    indices = frame_indices(source.frame_count, options.first, options.frames or source.default_frames,
                            options.stride)
    every = options.image_every or max(1, round(len(indices) / DEFAULT_IMAGE_COUNT))
    output = options.output
    (output / "frames").mkdir(parents=True, exist_ok=True)
    _remove_earlier_outputs(output)
    log = AnchorLog()
    files: list[Path] = []
    video: cv2.VideoWriter | None = None
    last_image: tuple[int, np.ndarray] | None = None
    interrupted = False
    started = time.perf_counter()
    say(f"replaying {len(indices)} frames of '{source.name}' (source frames {indices[0]}..{indices[-1]}, "
        f"stride {options.stride}): {source.description}")
    bar = progress_bar(len(indices), f"replay {source.name}", unit="frame")
    write = getattr(bar, "write", say)
    # Without a terminal the bar is silent: a progress line every tenth of the way stands in for it.
    checkpoint = max(1, len(indices) // 10) if not hasattr(bar, "write") else 0
    try:
        with bar:
            for number, frame in enumerate(source.frames(indices)):
                outcome = pipeline.step(frame)
                log.record(outcome, pipeline.anchoring)
                account = _account(outcome.result.events, outcome)
                if account:
                    write(f"frame {frame.index:>4}: {account}")
                image = annotate(outcome, pipeline.anchoring.anchors, source.name)
                if options.video:
                    if video is None:
                        video, video_path = _open_video(output, source.frame_rate / options.stride, image)
                        if video_path is not None:
                            files.append(video_path)
                    if video is not None:
                        video.write(image)
                if number % every == 0:
                    files.append(_write_png(output, frame.index, image))
                    last_image = None
                else:
                    last_image = (frame.index, image)
                bar.update(1)
                bar.set_postfix(anchors=len(pipeline.anchoring))
                if checkpoint and (number + 1) % checkpoint == 0:
                    say(f"[{number + 1}/{len(indices)} frames, {time.perf_counter() - started:.0f} s] "
                        f"{len(pipeline.anchoring)} anchors")
    except KeyboardInterrupt:
        interrupted = True
        say(f"interrupted after {log.frames} frames; writing what was processed")
    finally:
        if video is not None:
            video.release()
    if last_image is not None:
        files.append(_write_png(output, *last_image))
    seconds = time.perf_counter() - started
    processed = log.frames
    header = {
        "source": source.name, "description": source.description, "source_settings": source.settings(),
        "first_frame": indices[0], "last_frame": indices[min(processed, len(indices)) - 1] if processed else None,
        "stride": options.stride, "frame_rate": source.frame_rate, "seconds": round(seconds, 1),
        "interrupted": interrupted, **options.header,
    }
    json_path, markdown_path = log.write(output, header)
    files += [json_path, markdown_path]
    anchors = [record.as_dict() for record in log.records.values()]
    return ReplayReport(log.summary(), anchors, files, seconds, interrupted)


def _remove_earlier_outputs(folder: Path) -> None:
    """Delete the files an earlier replay wrote here, so frames of two runs never mix."""
    for path in (*(folder / "frames").glob("frame_*.png"), *(folder / name for _, name in VIDEO_FORMATS)):
        path.unlink(missing_ok=True)


def _account(events: tuple[AnchorEvent, ...], outcome: Any) -> str:
    """One line of what changed in a frame: acquisitions, confirmations, losses; '' if nothing."""
    parts = []
    for event in events:
        word = _ACCOUNTED.get(event.kind)
        if word is None:
            if event.kind is AnchorEventKind.REACQUIRED and event.details.get("was_missing"):
                word = "found again"
            else:
                continue
        tracker = event.details.get("tracker_id") if event.kind is AnchorEventKind.ACQUIRED else ""
        parts.append(f"{word} {event.symbol}" + (f" (track #{tracker})" if tracker else ""))
    return "; ".join(parts)


def _open_video(folder: Path, frame_rate: float, image: np.ndarray) -> tuple[cv2.VideoWriter | None, Path | None]:
    height, width = image.shape[:2]
    for fourcc, name in VIDEO_FORMATS:
        writer = cv2.VideoWriter(str(folder / name), cv2.VideoWriter_fourcc(*fourcc), frame_rate, (width, height))
        if writer.isOpened():
            return writer, folder / name
        writer.release()
    return None, None


def _write_png(folder: Path, index: int, image: np.ndarray) -> Path:
    path = folder / "frames" / f"frame_{index:06d}.png"
    if not cv2.imwrite(str(path), image):
        raise OSError(f"could not write {path}")
    return path


def format_summary(report: ReplayReport, limit: int = 25) -> str:
    """The final summary for the terminal: totals, then the anchors seen most often."""
    summary = report.summary
    states = ", ".join(f"{count} {state}" for state, count in sorted(summary["anchors_by_state"].items()))
    classes = ", ".join(f"{count} {name}" for name, count in summary["anchors_by_class"].items())
    dropped = ", ".join(f"{count} {reason}" for reason, count in summary["dropped_detections"].items()) or "none"
    timing = ", ".join(f"{stage} {value}" for stage, value in summary["milliseconds_per_frame"].items())
    lines = [
        f"{summary['frames']} frames in {report.seconds:.1f} s" + (" (interrupted)" if report.interrupted else ""),
        f"detections {summary['detections']}, percepts {summary['percepts']}, dropped: {dropped}",
        f"anchors {summary['anchors']} ({states or 'none'}); by class: {classes or 'none'}",
        f"tracker ids {summary['tracker_ids']}: {len(summary['tracker_ids_split_over_symbols'])} split over several "
        f"symbols, {len(summary['symbols_joining_tracker_ids'])} symbols joined several tracker ids",
        f"milliseconds per frame: {timing}",
    ]
    anchors = sorted(report.anchors, key=lambda anchor: -anchor["times_seen"])
    if anchors:
        lines.append(f"{'symbol':<16} {'class':<12} {'position (m)':<24} {'seen':>5}  state")
        for anchor in anchors[:limit]:
            position = ", ".join(f"{value:6.2f}" for value in anchor["position_m"])
            lines.append(f"{anchor['symbol']:<16} {anchor['class']:<12} {position:<24} "
                         f"{anchor['times_seen']:>5}  {anchor['state']}")
        if len(anchors) > limit:
            lines.append(f"... and {len(anchors) - limit} more in anchors.md")
    return "\n".join(lines)
