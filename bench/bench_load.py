"""Load test: 50 detections per frame at 30 Hz through the real nodes over DDS, then 3x overload.

The same graph as bench_pipeline.py (player with ground-truth detections -> percept_generator ->
anchoring -> knowledge_base, each a process), with 50 objects in view. Phase 1: 30 Hz for
``--duration`` seconds (default 300; --quick 7): memory must stay flat within 10 % after
warm-up, and the latency must not drift (no queue that fills). Phase 2: 90 Hz for 30 s (--quick 3),
more than the nodes can process, to see what they do with frames they cannot keep up with:
dropped (and how many, per node) and how stale the frames they do process are ("frames behind").
The requirement is newest-wins with counted drops, as the detector does. Nothing is asserted;
test/ros/test_pipeline_latency.py checks the behaviour on the short form.

Run: python bench/bench_load.py [--quick] [--duration S] [--node-log PATH] [--json PATH]
"""

from __future__ import annotations

from pathlib import Path

from bench_pipeline import extend
from harness import script
from harness.pipeline_figures import build
from harness.pipeline_run import PipelineConfig, isolate_ros_domain, phases_of, run_pipeline
from harness.results import BenchmarkResult

OBJECTS = 50
LOAD_PHASE = "30 Hz, 50 objects"
OVERLOAD_RATE_HZ = 90.0


def load_config(quick: bool, duration: float = 0.0) -> PipelineConfig:
    long_seconds = duration or (7.0 if quick else 300.0)
    return PipelineConfig(objects=OBJECTS, sample_period=0.5 if quick else 2.0, drain_seconds=1.0, phases=phases_of([
        (LOAD_PHASE, 30.0, long_seconds, min(2.0 if quick else 10.0, long_seconds / 4)),
        (f"overload {OVERLOAD_RATE_HZ:g} Hz", OVERLOAD_RATE_HZ, 3.0 if quick else 30.0, 1.0 if quick else 3.0),
    ]))


def run(quick: bool = False, duration: float = 0.0, node_log: Path | None = None) -> BenchmarkResult:
    config = load_config(quick, duration)
    result = BenchmarkResult(
        "load", f"Load: {OBJECTS} detections per frame at 30 Hz over DDS, then {OVERLOAD_RATE_HZ:g} Hz",
        "frame_player -> percept_generator -> anchoring -> knowledge_base, each its own process, shipped "
        "configuration. Phases: " + ", ".join(
            f"{p.label} for {p.seconds:g} s (first {p.settle_seconds:g} s not measured)" for p in config.phases)
        + f". Memory and CPU of each process sampled every {config.sample_period:g} s.",
        parameters={"objects": OBJECTS, "phases": [p.__dict__ for p in config.phases],
                    "sample_period": config.sample_period},
    )
    print(f"  playing {' then '.join(p.label + f' for {p.seconds:g} s' for p in config.phases)}", flush=True)
    recording = run_pipeline(config, echo=lambda line: print(f"  {line}", flush=True))
    return build(recording, result, LOAD_PHASE, node_log)


def main() -> int:
    isolate_ros_domain()
    return script.main(run, __doc__, extend=extend)


if __name__ == "__main__":
    raise SystemExit(main())
