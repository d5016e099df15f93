"""A pipeline recording, analysed, as a BenchmarkResult: figures, tables, latency and memory plots."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

from harness.pipeline_analysis import PhaseStatistics, analyse
from harness.pipeline_run import NODE_LABELS, Recording
from harness.results import BenchmarkResult, DistributionPlot, LinePlot, Table, percentile

LATENCY_TARGET_MS = 100.0
KEEP_UP_FRACTION = 0.95
MEMORY_FLAT_PERCENT = 10.0


def _round(value: float, digits: int = 1) -> float | None:
    return round(float(value), digits) if math.isfinite(value) else None


def describe_run(recording: Recording, statistics: Sequence[PhaseStatistics], result: BenchmarkResult,
                 targets_for: str = "") -> None:
    """Add the recording's figures, tables and plots to ``result``.

    ``targets_for`` names the phase the issue's targets apply to (p95 < 100 ms, keeping up with
    the input, memory flat within 10 %); other phases get their figures without a target.
    """
    for stats in statistics:
        with_targets = stats.label == targets_for
        p95 = stats.latency(0.95)
        result.figure(f"{stats.label}: latency p50", stats.latency(0.5), "ms")
        result.figure(f"{stats.label}: latency p95", p95, "ms",
                      **({"target": f"< {LATENCY_TARGET_MS:.0f} ms", "met": p95 < LATENCY_TARGET_MS}
                         if with_targets else {}))
        result.figure(f"{stats.label}: latency max", max(stats.latencies_ms, default=math.nan), "ms")
        keeps_up = stats.output_rate_hz >= KEEP_UP_FRACTION * stats.input_rate_hz
        result.figure(f"{stats.label}: AnchorArray rate", stats.output_rate_hz, "Hz", baseline=stats.input_rate_hz,
                      baseline_name="camera input rate", better="higher",
                      **({"target": f"keeps up (>= {KEEP_UP_FRACTION:.0%} of input)", "met": keeps_up}
                         if with_targets else {}))
        result.figure(f"{stats.label}: frames dropped", stats.dropped, f"of {stats.frames} frames")
    first = next((s for s in statistics if s.label == targets_for), None)
    if first is not None:
        for label, trend in sorted(first.memory.items()):
            if label not in NODE_LABELS:
                continue  # the player is the harness, not a node under test
            result.figure(f"{first.label}: RSS growth after warm-up, {label}", trend.growth_percent, "%",
                          target=f"flat within {MEMORY_FLAT_PERCENT:.0f} %",
                          met=abs(trend.growth_percent) <= MEMORY_FLAT_PERCENT)

    result.tables.append(Table(
        "per phase (measured frames only; latency = camera stamp -> AnchorArray published)",
        ["phase", "frames", "input Hz", "output Hz", "dropped: percept_generator", "dropped: anchoring",
         "p50 ms", "p95 ms", "p99 ms", "max ms", "stamp -> PerceptArray p50 ms", "frames behind p95 / max",
         "latency drift ms", "backlog at phase end", "anchors", "player late ticks"],
        [[s.label, s.frames, _round(s.input_rate_hz), _round(s.output_rate_hz), s.dropped_percept_generator,
          s.dropped_anchoring, _round(s.latency(0.5)), _round(s.latency(0.95)), _round(s.latency(0.99)),
          _round(max(s.latencies_ms, default=math.nan)), _round(percentile(s.percept_latencies_ms, 0.5)),
          f"{_round(s.summary()['frames_behind']['p95'], 0)} / {max(s.frames_behind, default=0)}",
          _round(s.latency_drift_ms), s.backlog, s.anchors_at_end, s.late_ticks] for s in statistics]))
    result.tables.append(Table(
        "per node (RSS: median of the first and last fifth of each phase's samples; CPU: % of one core)",
        ["phase", "node", "RSS start MB", "RSS end MB", "peak MB", "growth %", "slope MB/min", "CPU %"],
        [[s.label, label, _round(t.start_mb), _round(t.end_mb), _round(t.peak_mb), _round(t.growth_percent, 2),
          _round(t.slope_mb_per_minute, 2), _round(t.cpu_percent)]
         for s in statistics for label, t in sorted(s.memory.items())]))
    result.distributions.append(DistributionPlot(
        f"{result.name}_latency", f"{result.name}: camera stamp -> AnchorArray published", "ms",
        {s.label: [round(v, 3) for v in s.latencies_ms] for s in statistics}))

    phases = recording.played["phases"]
    samples = [sample for sample in recording.samples  # while frames flowed: not start-up, not shutdown
               if phases and phases[0]["started_ns"] <= sample[0] <= phases[-1]["ended_ns"]]
    if samples:
        origin = phases[0]["started_ns"]
        labels = sorted({label for _, values in samples for label in values})
        result.line_plots.append(LinePlot(
            f"{result.name}_memory", f"{result.name}: resident memory of each process while frames flow",
            "seconds since the first frame", "RSS (MB)",
            [round((time - origin) * 1e-9, 2) for time, _ in samples],
            {label: [round(values[label][0], 2) if label in values else None for _, values in samples]
             for label in labels},
            vertical_lines={phase["label"]: round((phase["started_ns"] - origin) * 1e-9, 2)
                            for phase in phases}))
    result.extra["phases"] = [s.summary() for s in statistics]
    result.extra["pids"] = recording.pids
    result.extra["node_outcomes"] = recording.outcomes
    result.extra["player_publish_ms"] = recording.played.get("publish_ms", {})
    reports = [line for line in recording.log if "percept arrays in the last" in line]
    if reports:
        result.notes.append(f"percept_generator's last statistics line: {reports[-1].split(']: ', 1)[-1]}")
    if not recording.ended_cleanly:
        result.notes.append("some nodes did NOT end cleanly: " + ", ".join(
            f"{o['label']} {o['ending']} ({o['return_code']})" for o in recording.outcomes if not o["clean"]))
    result.notes.append(
        "frames dropped are counted from the topics (a frame with no PerceptArray was dropped by "
        "percept_generator; a PerceptArray with no AnchorArray or events, by anchoring); 'frames behind' is how "
        "many newer frames the camera had already sent when a frame's AnchorArray went out (newest-wins keeps it "
        "at 1-2 per stage, a FIFO queue lets it grow to the queue's depth); 'backlog at phase end' counts the phase's "
        "frames anchored after its last frame was sent (still queued then)")


def build(recording: Recording, result: BenchmarkResult, targets_for: str, node_log: Path | None) -> BenchmarkResult:
    statistics = analyse(recording.played, recording.percepts, recording.anchors, recording.events,
                         recording.samples)
    describe_run(recording, statistics, result, targets_for)
    if node_log is not None:
        node_log.parent.mkdir(parents=True, exist_ok=True)
        node_log.write_text("\n".join(recording.log) + "\n")
        result.extra["node_log"] = str(node_log)
    return result
