"""Percept-to-anchor latency and throughput across the robot/laptop split, with and without Wi-Fi impairment.

Run as root: ``python bench/bench_network_split.py [--seconds 20] [--rate 10] [--crops 8,64] [--quick] [--json PATH]``.
It prints figures and asserts nothing (test/ros/test_faults.py has the short form that CI runs).

The paper's TIAGo set-up: perception on the robot, anchoring and the knowledge base on a laptop,
over Wi-Fi. Here the two computers are two network namespaces (test/ros/network_split.py): the
perceptual layer (``split_roles.py camera``: camera info, camera pose and a PerceptArray of three
objects per frame, each percept with a square RGB crop) publishes from ``robot``; the anchoring and
knowledge_base nodes and an observer run in ``laptop``. The observer notes when each frame's anchor
events arrive; both namespaces share one clock, so percept stamp to arrival is the latency.

Per crop size, two runs: the link as it is (baseline) and the link with netem's ``delay 50ms 10ms
loss 5%`` in each direction. Where the kernel has no sch_netem, the impaired link is the userspace
relay (test/ros/tun_relay.py), and so is its baseline (the relay with no impairment), so the ratio
compares like with like; a direct veth run is added for reference. Percepts are best effort (the
sensor-data QoS), so a lost datagram loses the frame: a crop of N pixels squared makes the array
about 3N^2 bytes per object, split into that many 1500-byte IP fragments, any of which lost
loses the whole frame.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import statistics
import sys
import tempfile
import time
import uuid
from pathlib import Path
from typing import Any

REPOSITORY = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPOSITORY / "bench"))
sys.path.insert(0, str(REPOSITORY / "test" / "ros"))  # the split lives with the tests that use it

import network_split  # noqa: E402
from harness import script  # noqa: E402
from harness.results import BenchmarkResult, DistributionPlot, Table  # noqa: E402

SPLIT_ROLES = REPOSITORY / "test" / "ros" / "split_roles.py"
VENV_BIN = Path(sys.executable).parent
OBJECTS = 3
DISCOVERY_SECONDS = 2.0


def measure(impairment: Any, link: str, seconds: float, rate: float, crop_pixels: int) -> dict[str, Any]:
    """One run: frames published, frames anchored, latencies (ms) and the link that carried them."""
    python, roles = sys.executable, str(SPLIT_ROLES)
    namespace = f"/kb_{uuid.uuid4().hex[:8]}"
    with tempfile.TemporaryDirectory() as state, network_split.NetworkSplit(impairment, link=link) as split:
        split.start("laptop", [str(VENV_BIN / "knowledge_base"), "--ros-args", "-r", f"__ns:={namespace}"])
        split.start("laptop", [str(VENV_BIN / "anchoring"), "--ros-args", "-p", f"state_folder:={state}",
                               "-p", f"knowledge_base:=ros://{namespace}"])
        # The observer listens until it is stopped: it never sees the thousand anchors it waits for.
        observer = split.start("laptop", [python, roles, "observe", "--expect-anchors", "1000",
                                          "--timeout", str(seconds + 120.0), "--keep-samples"])
        time.sleep(DISCOVERY_SECONDS)
        # The camera starts its clock once the anchoring node has subscribed: discovery is not measured.
        camera = split.start("robot", [python, roles, "camera", "--rate", str(rate), "--objects", str(OBJECTS),
                                       "--crop-pixels", str(crop_pixels), "--duration", str(seconds)])
        camera.process.wait(timeout=seconds + 60.0)
        time.sleep(2.0)  # the last frames cross the link
        camera.stop()
        observer.stop()
        published = _last_json(camera.text)
        observed = _last_json(observer.text)
        link_kind, impairment_by = split.link_kind, split.impairment_by
    relay = json.loads(split.relay_counts) if split.relay_counts.startswith("{") else {}
    latencies = observed.get("latencies_ms", [])
    sent = published.get("published", 0)
    return {
        "link": link_kind, "impairment_by": impairment_by, "impairment": str(impairment), "crop_pixels": crop_pixels,
        "published": sent, "anchored": len(latencies), "delivered": len(latencies) / sent if sent else 0.0,
        "frames_per_second": len(latencies) / seconds, "latencies_ms": latencies,
        "median_ms": statistics.median(latencies) if latencies else float("nan"),
        "p95_ms": latencies[int(0.95 * (len(latencies) - 1))] if latencies else float("nan"),
        "max_ms": max(latencies) if latencies else float("nan"), "relay": relay,
    }


def _last_json(text: str) -> dict[str, Any]:
    for line in reversed(text.strip().splitlines()):
        if line.startswith("{"):
            return json.loads(line)
    return {}


def run(quick: bool = False, seconds: float = 0.0, rate: float = 10.0, crops: str = "8,64") -> BenchmarkResult:
    reason = network_split.unavailable_reason()
    if reason is not None:  # a report that says why beats a failed run: most machines forbid namespaces
        print(f"skipped: {reason}", flush=True)
        return BenchmarkResult("network_split", "Percept-to-anchor latency across the robot/laptop split",
                               "Not measured on this machine.", notes=[f"skipped: {reason}"])
    os.environ["ROS_DOMAIN_ID"] = str(random.randint(101, 200))
    os.environ.setdefault("ROS_LOG_DIR", tempfile.mkdtemp(prefix="sailor-bench-ros-logs-"))
    os.environ["RCUTILS_COLORIZED_OUTPUT"] = "0"
    seconds = seconds or (8.0 if quick else 20.0)
    crop_sizes = [int(value) for value in crops.split(",")][: 1 if quick else None]
    wifi = network_split.TIAGO_WIFI
    probe = network_split.NetworkSplit(wifi)
    with probe:
        impaired_link = probe.link_kind  # veth where the kernel has netem, else the userspace relay
    result = BenchmarkResult(
        "network_split", "Percept-to-anchor latency and throughput across the robot/laptop split",
        f"Perception in one network namespace, anchoring and the knowledge base in another; {OBJECTS} objects per "
        f"frame at {rate:g} Hz for {seconds:g} s per run. Impaired: {wifi} in each direction "
        f"({probe.impairment_by}). Baseline: the same link without impairment.",
        parameters={"seconds": seconds, "rate_hz": rate, "objects": OBJECTS, "crop_pixels": crop_sizes,
                    "impaired_link": impaired_link},
    )
    rows, samples = [], {}
    for crop in crop_sizes:
        runs = {"baseline": measure(network_split.NO_IMPAIRMENT, impaired_link, seconds, rate, crop),
                "impaired": measure(wifi, impaired_link, seconds, rate, crop)}
        if impaired_link != "veth":
            runs["veth"] = measure(network_split.NO_IMPAIRMENT, "veth", seconds, rate, crop)
        for name, measured in runs.items():
            print(f"  crop {crop:>3} px, {name:>8} ({measured['link']}, {measured['impairment']}): "
                  f"{measured['anchored']}/{measured['published']} frames anchored, median "
                  f"{measured['median_ms']:.1f} ms, p95 {measured['p95_ms']:.1f} ms", flush=True)
            rows.append([crop, name, measured["link"], measured["impairment"], measured["published"],
                         measured["anchored"], round(100.0 * measured["delivered"], 1),
                         round(measured["frames_per_second"], 2), round(measured["median_ms"], 1),
                         round(measured["p95_ms"], 1), round(measured["max_ms"], 1)])
            samples[f"crop {crop} px, {name}"] = measured["latencies_ms"]
        baseline, impaired = runs["baseline"], runs["impaired"]
        result.figure(f"median percept-to-anchor latency, crop {crop} px, impaired", impaired["median_ms"], "ms",
                      baseline=baseline["median_ms"], baseline_name="same link, no impairment", better="lower")
        result.figure(f"frames anchored per second, crop {crop} px, impaired", impaired["frames_per_second"],
                      "frames/s", baseline=baseline["frames_per_second"], baseline_name="same link, no impairment",
                      better="higher")
        result.extra[f"crop_{crop}"] = {name: {k: v for k, v in measured.items() if k != "latencies_ms"}
                                        for name, measured in runs.items()}
    result.tables.append(Table("runs", ["crop px", "run", "link", "impairment", "published", "anchored",
                                        "delivered %", "frames/s", "median ms", "p95 ms", "max ms"], rows))
    result.distributions.append(DistributionPlot("network_split_latency", "Percept-to-anchor latency", "ms", samples))
    result.notes.append("Noisy: other work shares this machine's two cores; one run per condition.")
    if impaired_link != "veth":
        result.notes.append("This kernel has no sch_netem: the impairment is applied by a userspace relay "
                            "(test/ros/tun_relay.py), whose own cost is in the baseline too.")
    return result


def main() -> int:
    def extend(parser: argparse.ArgumentParser) -> None:
        parser.add_argument("--seconds", type=float, default=0.0, help="seconds per run (default 20, quick 8)")
        parser.add_argument("--rate", type=float, default=10.0, help="camera frames per second")
        parser.add_argument("--crops", default="8,64", help="crop sizes in pixels, comma separated (quick: the first)")

    return script.main(run, __doc__, extend=extend)


if __name__ == "__main__":
    raise SystemExit(main())
