"""What a replay did to every anchor, and the summary files it leaves behind.

The anchoring core keeps the anchors that are not forgotten; the log keeps every anchor the
replay ever made, frame by frame: the frames it was seen in, the tracker ids it took over, its
latest state and position. Without ground truth, two figures hint at identity errors:

- a tracker id split over several symbols: ByteTrack followed one track, the anchoring layer
  gave it more than one symbol (a switch, or a track that jumped to another object);
- a symbol holding several tracker ids: the anchoring layer recognised a new track as a known
  object (a re-identification after the tracker lost it, or a merge of two objects).

``anchors.json`` holds everything; ``anchors.md`` a table for people.
"""

from __future__ import annotations

import json
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from merlin2_sailor.anchoring.anchor import Anchor, AnchorState
from merlin2_sailor.anchoring.anchoring import Anchoring
from merlin2_sailor_demos.replay.pipeline import FrameOutcome


@dataclass(slots=True)
class AnchorRecord:
    """One anchor over the replay."""

    symbol: str
    class_name: str
    first_frame: int
    last_frame: int
    frames_seen: int = 0
    tracker_ids: list[str] = field(default_factory=list)
    state: str = AnchorState.TENTATIVE.value
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    size: tuple[float, float, float] = (0.0, 0.0, 0.0)
    times_seen: int = 0
    first_position: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def as_dict(self) -> dict[str, Any]:
        return {
            "symbol": self.symbol, "class": self.class_name, "state": self.state,
            "position_m": [round(value, 3) for value in self.position],
            "size_m": [round(value, 3) for value in self.size],
            "times_seen": self.times_seen, "frames_seen": self.frames_seen,
            "first_frame": self.first_frame, "last_frame": self.last_frame,
            "moved_m": round(float(np.linalg.norm(np.subtract(self.position, self.first_position))), 3),
            "tracker_ids": self.tracker_ids,
        }


class AnchorLog:
    """``record(outcome, anchoring)`` after each frame; ``summary()`` and ``write(folder)`` at the end."""

    def __init__(self) -> None:
        self.records: dict[str, AnchorRecord] = {}
        self.frames = 0
        self.detections = 0
        self.percepts = 0
        self.dropped: Counter[str] = Counter()
        self.events: Counter[str] = Counter()
        self.seconds: Counter[str] = Counter()
        self._symbols_of_tracker: dict[str, list[str]] = {}

    def record(self, outcome: FrameOutcome, anchoring: Anchoring) -> None:
        index = outcome.frame.index
        self.frames += 1
        self.detections += len(outcome.boxes)
        self.percepts += len(outcome.percepts)
        self.seconds.update(outcome.seconds)
        self.events.update(event.kind.value for event in outcome.result.events)
        for box in outcome.boxes:
            if not box.symbol:
                self.dropped[box.drop_reason] += 1
                continue
            record = self.records.get(box.symbol)
            if record is None:
                record = AnchorRecord(box.symbol, box.detection.class_name, index, index)
                self.records[box.symbol] = record
            record.frames_seen += 1
            record.last_frame = index
            tracker_id = box.detection.tracker_id
            if tracker_id:
                if tracker_id not in record.tracker_ids:
                    record.tracker_ids.append(tracker_id)
                symbols = self._symbols_of_tracker.setdefault(tracker_id, [])
                if box.symbol not in symbols:
                    symbols.append(box.symbol)
        for anchor in outcome.result.acquired:
            self._update(anchor, first=True)
        for anchor in (*outcome.result.reacquired, *outcome.result.missing):
            self._update(anchor)
        for anchor in outcome.result.forgotten:
            self._update(anchor)
            self.records[anchor.symbol].state = AnchorState.FORGOTTEN.value

    def _update(self, anchor: Anchor, first: bool = False) -> None:
        record = self.records.get(anchor.symbol)
        if record is None:  # an anchor restored or made outside this log's frames
            return
        record.class_name = anchor.class_name
        record.state = anchor.state.value
        record.position = tuple(float(value) for value in anchor.position)  # type: ignore[assignment]
        record.size = tuple(float(value) for value in anchor.size)  # type: ignore[assignment]
        record.times_seen = anchor.times_seen
        if first:
            record.first_position = record.position

    # --- summary -------------------------------------------------------------------------------

    @property
    def split_tracks(self) -> dict[str, list[str]]:
        """Tracker ids anchored to more than one symbol."""
        return {tracker: symbols for tracker, symbols in self._symbols_of_tracker.items() if len(symbols) > 1}

    @property
    def joined_tracks(self) -> dict[str, list[str]]:
        """Symbols that took over more than one tracker id."""
        return {symbol: record.tracker_ids for symbol, record in self.records.items() if len(record.tracker_ids) > 1}

    def summary(self) -> dict[str, Any]:
        states = Counter(record.state for record in self.records.values())
        classes = Counter(record.class_name for record in self.records.values())
        frames = max(self.frames, 1)
        return {
            "frames": self.frames,
            "detections": self.detections,
            "percepts": self.percepts,
            "dropped_detections": dict(self.dropped),
            "anchors": len(self.records),
            "anchors_by_state": dict(states),
            "anchors_by_class": dict(classes.most_common()),
            "events": dict(self.events),
            "tracker_ids": len(self._symbols_of_tracker),
            "tracker_ids_split_over_symbols": self.split_tracks,
            "symbols_joining_tracker_ids": self.joined_tracks,
            "milliseconds_per_frame": {stage: round(1000 * total / frames, 1) for stage, total in self.seconds.items()},
        }

    def write(self, folder: Path, header: dict[str, Any]) -> tuple[Path, Path]:
        """Write ``anchors.json`` and ``anchors.md`` into ``folder``; return their paths."""
        folder.mkdir(parents=True, exist_ok=True)
        anchors = [record.as_dict() for record in sorted(self.records.values(), key=_symbol_order)]
        report = {**header, "summary": self.summary(), "anchors": anchors}
        json_path = folder / "anchors.json"
        json_path.write_text(json.dumps(report, indent=2) + "\n")
        markdown_path = folder / "anchors.md"
        markdown_path.write_text(self.markdown(header, anchors))
        return json_path, markdown_path

    def markdown(self, header: dict[str, Any], anchors: list[dict[str, Any]]) -> str:
        summary = self.summary()
        states = ", ".join(f"{count} {state}" for state, count in sorted(summary["anchors_by_state"].items()))
        classes = ", ".join(f"{count} {name}" for name, count in summary["anchors_by_class"].items())
        lines = [
            f"# Replay of `{header.get('source', '?')}`",
            "",
            str(header.get("description", "")),
            "",
            f"- frames: {summary['frames']} (source frames {header.get('first_frame', '?')}.."
            f"{header.get('last_frame', '?')}, stride {header.get('stride', 1)}); detector "
            f"`{header.get('detector', '?')}`, matcher `{header.get('matcher', '?')}`",
            f"- detections: {summary['detections']}; percepts: {summary['percepts']}; dropped: "
            + (", ".join(f"{count} {reason}" for reason, count in summary["dropped_detections"].items()) or "none"),
            f"- anchors: {summary['anchors']} ({states or 'none'}); by class: {classes or 'none'}",
            f"- tracker ids: {summary['tracker_ids']}; split over several symbols: "
            f"{len(summary['tracker_ids_split_over_symbols'])}; symbols joining several tracker ids: "
            f"{len(summary['symbols_joining_tracker_ids'])}",
            "- milliseconds per frame: "
            + ", ".join(f"{stage} {value}" for stage, value in summary["milliseconds_per_frame"].items()),
            "",
            "Positions are anchor centres in the world frame (x forward, y left, z up, metres); "
            "`moved` is how far the anchor's position went from where it was acquired.",
            "",
            "| symbol | class | position (m) | size (m) | times seen | frames | moved (m) | tracker ids | state |",
            "| --- | --- | --- | --- | ---: | --- | ---: | --- | --- |",
        ]
        for anchor in anchors:
            position = ", ".join(f"{value:.2f}" for value in anchor["position_m"])
            size = " x ".join(f"{value:.2f}" for value in anchor["size_m"])
            lines.append(
                f"| {anchor['symbol']} | {anchor['class']} | ({position}) | {size} | {anchor['times_seen']} | "
                f"{anchor['first_frame']}-{anchor['last_frame']} | {anchor['moved_m']:.2f} | "
                f"{', '.join(anchor['tracker_ids']) or '-'} | {anchor['state']} |"
            )
        return "\n".join(lines) + "\n"


def _symbol_order(record: AnchorRecord) -> tuple[str, int]:
    prefix, _, number = record.symbol.rpartition("_")
    return (prefix, int(number)) if number.isdigit() else (record.symbol, 0)
