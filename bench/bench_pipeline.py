"""End-to-end frame latency through the real nodes over DDS, and their memory over a long run.

A player process sends 640x480 RGB-D frames, the camera pose and ground-truth detections of 10
objects (the detector is left out) into the real ``percept_generator`` and ``anchoring`` nodes,
with ``knowledge_base`` behind them, each a process started by the project's launcher with its
shipped configuration. Each AnchorArray is matched to the frame it came from (see
harness/pipeline_analysis.py); its latency is camera stamp -> AnchorArray published. Phases: 15 Hz
for ``--duration`` seconds (default 600; the memory run), then 30 Hz for 60 s; --quick: 10 s and
5 s. Each process's resident memory and CPU time are sampled from /proc throughout. Targets
(issue 9): keeps up with 15 Hz with p95 < 100 ms on a 2-core CPU; memory flat within 10 % after
warm-up. Nothing is asserted.

Run: python bench/bench_pipeline.py [--quick] [--duration S] [--node-log PATH] [--json PATH]
"""

from __future__ import annotations

import argparse
from pathlib import Path

from harness import script
from harness.pipeline_figures import build
from harness.pipeline_run import PipelineConfig, isolate_ros_domain, phases_of, run_pipeline
from harness.results import BenchmarkResult

OBJECTS = 10
TARGET_PHASE = "15 Hz"


def run(quick: bool = False, duration: float = 0.0, node_log: Path | None = None) -> BenchmarkResult:
    long_seconds = duration or (10.0 if quick else 600.0)
    phases = phases_of([
        (TARGET_PHASE, 15.0, long_seconds, min(2.0 if quick else 10.0, long_seconds / 4)),
        ("30 Hz", 30.0, 5.0 if quick else 60.0, 1.5 if quick else 5.0),
    ])
    config = PipelineConfig(objects=OBJECTS, phases=phases, sample_period=0.5 if quick else 2.0,
                            drain_seconds=1.0)
    result = BenchmarkResult(
        "pipeline", f"End-to-end latency over DDS, {OBJECTS} objects in view at 640x480, detector excluded",
        "frame_player -> percept_generator -> anchoring -> knowledge_base, each its own process (shipped "
        "configuration: ByteTrack, rule matcher, knowledge base synced every 0.5 s). Phases: "
        + ", ".join(f"{p.label} for {p.seconds:g} s (first {p.settle_seconds:g} s not measured)" for p in phases)
        + f". Memory and CPU of each process sampled every {config.sample_period:g} s.",
        parameters={"objects": OBJECTS, "phases": [p.__dict__ for p in phases], "sample_period": config.sample_period},
    )
    print(f"  playing {' then '.join(p.label + f' for {p.seconds:g} s' for p in phases)}", flush=True)
    recording = run_pipeline(config, echo=lambda line: print(f"  {line}", flush=True))
    return build(recording, result, TARGET_PHASE, node_log)


def extend(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--duration", type=float, default=0.0, metavar="S",
                        help="seconds of the long (memory) phase (default 600, quick 13)")
    parser.add_argument("--node-log", type=Path, default=None, metavar="PATH", help="write the nodes' output here")


def main() -> int:
    isolate_ros_domain()
    return script.main(run, __doc__, extend=extend)


if __name__ == "__main__":
    raise SystemExit(main())
