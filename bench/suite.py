"""The benchmark suite: run every benchmark of bench/ and write one report folder.

``sailor bench`` runs this script (``python bench/suite.py``, the same options); it is part of
the source checkout, like the benchmarks, and the installed package only locates it. Each
benchmark is a script of bench/ (``python bench/bench_x.py`` prints its figures on its own); here
each runs in a process of its own, as ``bench_x.py --json FILE``, so thread limits are set before
NumPy loads, memory figures start from a fresh heap and no benchmark disturbs the next. Their
output is the progress shown on the console. Then harness/report.py writes ``report.md`` (the
machine, then one table per benchmark with each figure beside its baseline measured in the same
run, and their ratio), ``results.json`` and the PNG plots.

Run: python bench/suite.py [--quick] [--only NAME ...] [--output DIR] [--duration S]
"""

from __future__ import annotations

import argparse
import json
import os
import shlex
import subprocess
import sys
import tempfile
import time
from collections import deque
from collections.abc import Sequence
from datetime import datetime
from pathlib import Path

from harness.machine import describe, load_average, summary
from harness.report import BenchmarkRun, write_report
from harness.results import BenchmarkResult

BENCH_FOLDER = Path(__file__).resolve().parent
#: How the report's header and the help name this command; ``sailor bench`` runs this script.
COMMAND = "sailor bench"

#: name -> (script in bench/, what it measures); the order they run in.
BENCHMARKS = {
    "percepts": ("bench_percepts.py", "percept generation per frame (3D boxes + crops) vs per-pixel Python"),
    "embedding": ("bench_embedding.py", "crop embedding per crop in torch, batched vs one at a time"),
    "inference": ("bench_inference.py", "embedding, detector and matching network on OpenVINO vs torch / OpenCV DNN, "
                                        "and the anchoring service's memory on each"),
    "matching": ("bench_matching.py", "matching table vs anchors (100..10,000) and percepts (1..50) vs per pair"),
    "assignment": ("bench_assignment.py", "Hungarian vs greedy and brute force"),
    "knowledge_sync": ("bench_knowledge_sync.py", "knowledge-base sync, one batch vs one call per change"),
    "anchoring_scale": ("bench_anchoring_scale.py", "anchoring per frame and memory as far anchors pile up"),
    "pipeline": ("bench_pipeline.py", "end-to-end latency over DDS at 15 and 30 Hz, memory over a long run"),
    "pipeline_detector": ("bench_pipeline_detector.py",
                          "the whole pipeline with the real detector and the learned matcher at 15 and 30 Hz, "
                          "new inference path (OpenVINO) vs old (OpenCV DNN + torch)"),
    "load": ("bench_load.py", "50 detections at 30 Hz then 90 Hz over DDS: memory, queues, drops"),
    "world_render": ("bench_world_render.py", "the simulated house's frame (render, depth, detections) vs 15 Hz"),
    "network_split": ("bench_network_split.py",
                      "latency and throughput across the robot/laptop split, impaired link vs clean "
                      "(needs network namespaces; skipped with the reason where they cannot be made)"),
}
#: Benchmarks that take --duration (their long phase) and write the nodes' output with --node-log.
GRAPH_BENCHMARKS = ("pipeline", "pipeline_detector", "load")
ERROR_LINES = 60



def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=COMMAND,
        description="Run every benchmark (or those named with --only), each in its own process, and write "
                    "report.md, results.json and PNG plots into --output. Benchmarks: "
                    + "; ".join(f"{name}: {text}" for name, (_, text) in BENCHMARKS.items()) + ".",
    )
    parser.add_argument("--quick", action="store_true",
                        help="the short form: smaller sizes and shorter runs (well under a minute in all)")
    parser.add_argument("--output", default="reports/bench", metavar="DIR",
                        help="report folder (default reports/bench)")
    parser.add_argument("--only", nargs="+", action="extend", choices=list(BENCHMARKS), metavar="NAME",
                        help=f"run only these ({', '.join(BENCHMARKS)})")
    parser.add_argument("--duration", type=float, default=0.0, metavar="S",
                        help="seconds of the long phase of pipeline (default 600) and load (default 300)")
    return parser


def command_line(arguments: argparse.Namespace) -> str:
    """The command as a user would type it, for the report's header."""
    words = COMMAND.split() + (["--quick"] if arguments.quick else [])
    words += ["--output", arguments.output] + (["--only", *arguments.only] if arguments.only else [])
    return shlex.join(words + (["--duration", f"{arguments.duration:g}"] if arguments.duration > 0.0 else []))


def benchmark_command(folder: Path, name: str, arguments: argparse.Namespace, json_file: Path,
                      output: Path) -> list[str]:
    command = [sys.executable, str(folder / BENCHMARKS[name][0]), "--json", str(json_file)]
    if arguments.quick:
        command.append("--quick")
    if name in GRAPH_BENCHMARKS:
        command += ["--node-log", str(output / "logs" / f"{name}_nodes.log")]
        if arguments.duration > 0.0:
            command += ["--duration", str(arguments.duration)]
    return command


def run_one(command: list[str], name: str) -> tuple[int, str]:
    """Run one benchmark's script, showing its output; returns its exit code and its last lines."""
    tail: deque[str] = deque(maxlen=ERROR_LINES)
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                               text=True, env={**os.environ, "PYTHONUNBUFFERED": "1"})
    assert process.stdout is not None
    try:
        for line in process.stdout:
            tail.append(line.rstrip("\n"))
            print(f"[{name}] {line.rstrip()}", flush=True)
        return process.wait(), "\n".join(tail)
    except KeyboardInterrupt:  # Ctrl-C reached the benchmark too: let it stop the nodes it started
        try:
            process.wait(timeout=30.0)
        except subprocess.TimeoutExpired:
            process.terminate()
            process.wait()
        raise


def run(arguments: argparse.Namespace) -> int:
    folder = BENCH_FOLDER
    selected = [name for name in BENCHMARKS if not arguments.only or name in arguments.only]
    output = Path(arguments.output).expanduser().resolve()
    machine = describe()
    started, clock = datetime.now().astimezone(), time.monotonic()
    print(f"machine: {summary(machine)}", flush=True)
    print(f"running {len(selected)} benchmark(s){' (quick)' if arguments.quick else ''}: {', '.join(selected)}",
          flush=True)
    runs = []
    with tempfile.TemporaryDirectory(prefix="sailor-bench-") as scratch:
        for number, name in enumerate(selected, start=1):
            json_file = Path(scratch) / f"{name}.json"
            command = benchmark_command(folder, name, arguments, json_file, output)
            print(f"[{number}/{len(selected)}] {name}: {shlex.join(command[1:])}", flush=True)
            begun = time.monotonic()
            try:
                code, tail = run_one(command, name)
            except KeyboardInterrupt:
                print(f"interrupted during {name}: no report written", file=sys.stderr, flush=True)
                return 130
            seconds = time.monotonic() - begun
            if code == 0 and json_file.is_file():
                runs.append(BenchmarkRun(name, seconds, BenchmarkResult.from_dict(json.loads(json_file.read_text()))))
                print(f"[{number}/{len(selected)}] {name}: done in {seconds:.1f} s", flush=True)
            else:
                runs.append(BenchmarkRun(name, seconds, error=f"exit code {code}\n{tail}"))
                print(f"[{number}/{len(selected)}] {name}: FAILED (exit code {code})", flush=True)
    header = {
        "command": command_line(arguments),
        "quick": arguments.quick, "started": started.isoformat(timespec="seconds"),
        "seconds": time.monotonic() - clock, "load_average_end": load_average(),
        "selected": selected,
    }
    paths = write_report(output, runs, machine, header)
    failed = [run.name for run in runs if not run.succeeded]
    print(f"wrote {paths['report']} and {paths['results']} ({sum(len(r.plots) for r in runs)} plots) "
          f"in {header['seconds']:.0f} s" + (f"; FAILED: {', '.join(failed)}" if failed else ""), flush=True)
    return 1 if failed else 0


def main(argv: Sequence[str] | None = None) -> int:
    return run(build_parser().parse_args(argv))


if __name__ == "__main__":
    sys.exit(main())
