"""From a pipeline recording to figures: latency, rates, drops per node, queueing, memory. ROS-free.

Correlation. Every message of a frame carries the camera stamp the player gave it; the percept
generator keeps it as the PerceptArray's stamp, and the anchoring node stamps each anchor's
``last_seen`` (and each event) with the percepts' stamp. The AnchorArray's own header holds the
time it was published. So an AnchorArray published after processing a frame is the first one
whose newest ``last_seen`` is that frame's stamp, and its latency is header stamp - frame stamp:
the camera stamp to AnchorArray published, on the one wall clock of this machine. AnchorArrays
published by the Track timer repeat an earlier newest ``last_seen`` and are not counted again.

Drops, per node, from what came out of it: a frame the percept generator never turned into a
PerceptArray was dropped there (the probe's own PerceptArray losses are recovered from the
anchoring outputs, which prove the array existed); a PerceptArray that never produced an
anchoring output (an AnchorArray or events stamped with it) was dropped by the anchoring node.

Queueing: for each anchored frame, the number of newer frames the player had already published
when its AnchorArray went out. A node that drops old frames for new ones keeps this at one or
two per stage; one that queues frames lets it grow to its queue's depth. And the backlog: how
many of a phase's frames were anchored after its last frame was sent, i.e. were still queued
somewhere then; bounded queues bound it whatever the machine's speed.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from harness.results import percentile

MATCH_TOLERANCE_NS = 1_000_000  # stamps go through float seconds on the way: sub-microsecond noise


@dataclass
class MemoryTrend:
    start_mb: float
    end_mb: float
    peak_mb: float
    growth_percent: float  # end vs start, each the median of a fifth of the window's samples
    slope_mb_per_minute: float
    cpu_percent: float  # of one core, over the window


@dataclass
class PhaseStatistics:
    label: str
    requested_rate_hz: float
    frames: int  # measured frames published
    input_rate_hz: float
    late_ticks: int  # schedule ticks the player itself was too late for
    percepts_out: int
    anchored: int
    dropped_percept_generator: int
    dropped_anchoring: int
    output_rate_hz: float
    latencies_ms: list[float]
    percept_latencies_ms: list[float]  # frame stamp -> PerceptArray received by the probe
    frames_behind: list[int]
    anchors_at_end: int
    backlog: int  # frames of the phase anchored after its last frame was sent: what was queued then
    memory: dict[str, MemoryTrend] = field(default_factory=dict)

    @property
    def dropped(self) -> int:
        return self.dropped_percept_generator + self.dropped_anchoring

    def latency(self, fraction: float) -> float:
        return percentile(self.latencies_ms, fraction)

    @property
    def latency_drift_ms(self) -> float:
        """Median latency of the window's last third minus its first third: > 0 when a queue fills."""
        third = len(self.latencies_ms) // 3
        if third < 3:
            return math.nan
        return percentile(self.latencies_ms[-third:], 0.5) - percentile(self.latencies_ms[:third], 0.5)

    def summary(self) -> dict[str, Any]:
        return {
            "label": self.label, "requested_rate_hz": self.requested_rate_hz, "frames": self.frames,
            "input_rate_hz": self.input_rate_hz, "output_rate_hz": self.output_rate_hz,
            "late_ticks": self.late_ticks, "percepts_out": self.percepts_out, "anchored": self.anchored,
            "dropped_percept_generator": self.dropped_percept_generator, "dropped_anchoring": self.dropped_anchoring,
            "latency_ms": {"p50": self.latency(0.5), "p95": self.latency(0.95), "p99": self.latency(0.99),
                           "max": max(self.latencies_ms, default=math.nan),
                           "mean": float(np.mean(self.latencies_ms)) if self.latencies_ms else math.nan},
            "percept_latency_ms_p50": percentile(self.percept_latencies_ms, 0.5),
            "frames_behind": {"p95": percentile(self.frames_behind, 0.95),
                              "max": max(self.frames_behind, default=0)},
            "latency_drift_ms": self.latency_drift_ms, "anchors_at_end": self.anchors_at_end,
            "backlog": self.backlog,
            "memory": {label: trend.__dict__ for label, trend in self.memory.items()},
        }


def match(published: np.ndarray, observed: Sequence[int], tolerance: int = MATCH_TOLERANCE_NS) -> np.ndarray:
    """Index into the sorted ``published`` stamps of each observed stamp; -1 where none is that close."""
    if len(published) == 0 or len(observed) == 0:
        return np.full(len(observed), -1, dtype=np.intp)
    values = np.asarray(observed, dtype=np.int64)
    right = np.searchsorted(published, values).clip(0, len(published) - 1)
    left = (right - 1).clip(min=0)
    nearest = np.where(np.abs(published[left] - values) <= np.abs(published[right] - values), left, right)
    return np.where(np.abs(published[nearest] - values) <= tolerance, nearest, -1)


def memory_trend(samples: Sequence[tuple[int, dict[str, tuple[float, float]]]], label: str, start_ns: int,
                 end_ns: int) -> MemoryTrend | None:
    window = [(time, values[label]) for time, values in samples if start_ns <= time <= end_ns and label in values]
    if len(window) < 3:
        return None
    times = np.array([time for time, _ in window], dtype=np.float64) * 1e-9
    rss = np.array([value[0] for _, value in window])
    cpu = np.array([value[1] for _, value in window])
    fifth = max(len(window) // 5, 1)
    start, end = float(np.median(rss[:fifth])), float(np.median(rss[-fifth:]))
    minutes = (times - times[0]) / 60.0
    slope = float(np.polyfit(minutes, rss, 1)[0]) if minutes[-1] > 0 else 0.0
    elapsed = times[-1] - times[0]
    return MemoryTrend(start, end, float(rss.max()), 100.0 * (end - start) / start if start else math.nan, slope,
                       100.0 * (cpu[-1] - cpu[0]) / elapsed if elapsed > 0 else math.nan)


def analyse(played: dict[str, Any], percepts: Sequence[tuple[int, int, int]],
            anchors: Sequence[tuple[int, int, int, int]], events: Sequence[tuple[int, tuple[int, ...]]],
            samples: Sequence[tuple[int, dict[str, tuple[float, float]]]] = ()) -> list[PhaseStatistics]:
    """Statistics of each phase the player played, over its measured frames."""
    frames = np.array(played["frames"], dtype=np.int64).reshape(-1, 3)
    order = np.argsort(frames[:, 0], kind="stable")
    frames = frames[order]
    stamps = frames[:, 0]

    # The first AnchorArray for each frame (by newest last_seen), and the frames anchoring answered at all.
    anchor_time = np.full(len(stamps), -1, dtype=np.int64)
    anchors_sorted = sorted(anchors, key=lambda record: record[1])
    for index, (_, published, _, _) in zip(match(stamps, [a[2] for a in anchors_sorted]), anchors_sorted,
                                           strict=True):
        if index >= 0 and anchor_time[index] < 0:
            anchor_time[index] = published
    answered = anchor_time >= 0
    for _, event_stamps in events:
        indices = match(stamps, list(event_stamps))
        answered[indices[indices >= 0]] = True
    percept_received = np.full(len(stamps), -1, dtype=np.int64)
    for index, (received, _, _) in zip(match(stamps, [p[1] for p in percepts]), percepts, strict=True):
        if index >= 0 and percept_received[index] < 0:
            percept_received[index] = received
    perceived = (percept_received >= 0) | answered

    statistics = []
    for phase_index, phase in enumerate(played["phases"]):
        selected = np.flatnonzero((frames[:, 1] == phase_index) & (frames[:, 2] == 1))
        period_ns = 1e9 / phase["rate_hz"]
        if len(selected) == 0:
            continue
        window_ns = stamps[selected[-1]] - stamps[selected[0]] + period_ns
        window_s = window_ns * 1e-9
        anchored = selected[anchor_time[selected] >= 0]
        latencies = ((anchor_time[anchored] - stamps[anchored]) * 1e-6).tolist()
        behind = (np.searchsorted(stamps, anchor_time[anchored], side="left") - 1 - anchored).clip(min=0).tolist()
        received = selected[percept_received[selected] >= 0]
        percept_latencies = ((percept_received[received] - stamps[received]) * 1e-6).tolist()
        phase_end = phase["ended_ns"]
        sent_last = stamps[np.flatnonzero(frames[:, 1] == phase_index)[-1]]
        last_anchor_count = [count for received_at, _, _, count in anchors if received_at <= phase_end + 2e9]
        stats = PhaseStatistics(
            label=phase["label"], requested_rate_hz=phase["rate_hz"], frames=len(selected),
            input_rate_hz=len(selected) / window_s, late_ticks=int(phase["late_ticks"]),
            percepts_out=int(perceived[selected].sum()), anchored=int(answered[selected].sum()),
            dropped_percept_generator=int((~perceived[selected]).sum()),
            dropped_anchoring=int((perceived[selected] & ~answered[selected]).sum()),
            output_rate_hz=len(anchored) / window_s, latencies_ms=latencies, percept_latencies_ms=percept_latencies,
            frames_behind=[int(b) for b in behind],
            anchors_at_end=last_anchor_count[-1] if last_anchor_count else 0,
            backlog=int((anchor_time[frames[:, 1] == phase_index] > sent_last).sum()),
        )
        start_ns = int(stamps[selected[0]])
        for label in sorted({label for _, values in samples for label in values}):
            trend = memory_trend(samples, label, start_ns, int(phase_end))
            if trend is not None:
                stats.memory[label] = trend
        statistics.append(stats)
    return statistics
