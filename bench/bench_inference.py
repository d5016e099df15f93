"""The networks the nodes run, through the OpenVINO runtime against the framework each was written in.

Three networks, each figure beside its baseline measured in the same run on the same inputs:

- crop embedding (EfficientNet-Lite0 + crop descriptor (colour and layout), the whole path of a percept's crop),
  ms per crop at batches of 1-16: OpenVINO against torch eager (channels-last);
- the SSD-MobileNet-v2 COCO detector, ms per frame on real photos (Debian darknet): OpenVINO
  against OpenCV DNN, both fed the same 300 px resize;
- the matching network's heads, ms per call for a frame's pairs: OpenVINO against torch;

each with 2 threads (the target machine: two cores) and 1 thread, OpenVINO in float32 (``f32``, as
torch; the matching path's default) and in the device's fastest precision (``auto``: bfloat16 on
CPUs with AVX-512 BF16 or AMX; torch and OpenCV DNN stay float32), the detector also quantised
to int8 (its default; ``merlin2_sailor.inference.quantisation``), and the resident memory of the
anchoring service with the learned matcher (its matcher and crop embedder built, a frame
embedded and scored), each runtime in a fresh process, and whether that process imported torch.
Targets (issue 16): embedding <= 5 ms/crop and >= 2.5x torch; detector <= 25 ms/frame and >= 2x
OpenCV DNN; the anchoring service's memory with the runtime below torch's. Nothing is asserted.

Run: python bench/bench_inference.py [--quick] [--json PATH]
"""

# ruff: noqa: E402 - bench/ goes on sys.path before the harness is imported
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import json
import subprocess
import textwrap
from collections.abc import Callable

import numpy as np
from harness import script
from harness.results import BenchmarkResult, Table, median_seconds
from harness.scene import photo_folder

from merlin2_sailor.anchoring.features import PairFeatures
from merlin2_sailor.anchoring.matcher_registry import MatcherSettings, create_matcher
from merlin2_sailor.inference.settings import DETECTOR_PRECISIONS, PRECISIONS, InferenceSettings
from merlin2_sailor.perception.detector_registry import create_detector
from merlin2_sailor.perception.embedding import CropEmbedder, EmbeddingConfig

PHOTOS = ("dog", "person", "horses", "giraffe", "kite", "eagle")
RUNTIMES = {"openvino": "OpenVINO", "native": "torch / OpenCV DNN"}


def load_photos() -> list[np.ndarray]:
    """The darknet photos as RGB; random pixels where the package is missing (the figures say so)."""
    import cv2

    folder = photo_folder()
    photos = []
    for name in PHOTOS:
        image = cv2.imread(str(folder / f"{name}.jpg"))
        if image is not None:
            photos.append(cv2.cvtColor(cv2.resize(image, (640, 480)), cv2.COLOR_BGR2RGB))
    if not photos:
        print(f"  no photos in {folder} (scripts/fetch_test_data.sh fetches them): random frames", flush=True)
        photos = [np.random.default_rng(k).integers(0, 255, (480, 640, 3), np.uint8) for k in range(3)]
    return photos


def crops_of(photos: list[np.ndarray], count: int, seed: int = 0) -> list[np.ndarray]:
    """Crops of 40-300 px, the sizes a detector's boxes give at 640x480."""
    rng = np.random.default_rng(seed)
    crops = []
    for index in range(count):
        image = photos[index % len(photos)]
        width, height = rng.integers(40, 300, 2)
        x, y = rng.integers(0, 640 - width), rng.integers(0, 480 - height)
        crops.append(image[y: y + height, x: x + width])
    return crops


def frame_pairs(count: int, dimension: int) -> PairFeatures:
    """``count`` same-class pairs with appearance, features in their usual ranges (what one frame scores)."""
    rng = np.random.default_rng(count)
    distance, elapsed = rng.uniform(0.0, 3.0, count), rng.uniform(0.0, 60.0, count)
    widths_apart = distance / rng.uniform(0.05, 1.5, count)
    difference = np.abs(rng.normal(0.0, 0.5, (count, dimension))).astype(np.float32)
    return PairFeatures(
        rows=np.arange(count), columns=np.arange(count), same_class=np.ones(count, dtype=bool), distance=distance,
        footprint_distance=distance, place_distance=distance, distance_score=np.exp(-distance), separation=widths_apart,
        separation_score=np.exp(-widths_apart), scale=rng.uniform(0.7, 1.4, count),
        time_difference=elapsed, time_score=np.exp(-elapsed / 30.0), searched=np.zeros(count, dtype=bool),
        appearance_known=np.ones(count, dtype=bool), appearance_distance=difference.sum(axis=1),
        appearance_difference=difference)


def settings(runtime: str, threads: int, precision: str) -> InferenceSettings:
    return InferenceSettings(runtime=runtime, threads=threads, precision=precision)


def compare(result: BenchmarkResult, rows: list[list[object]], label: str, unit: str,
            measure: Callable[[str], float], target: str = "", target_value: float | None = None) -> None:
    """Measure ``label`` on both runtimes; the figure is OpenVINO's with torch / OpenCV as baseline."""
    runtime_value, baseline = measure("openvino"), measure("native")
    met = None if target_value is None else runtime_value <= target_value
    result.figure(label, runtime_value, unit, baseline=baseline, baseline_name=RUNTIMES["native"], target=target,
                  met=met)
    rows.append([label, round(runtime_value, 2), round(baseline, 2), round(baseline / runtime_value, 2)])
    print(f"  {label}: OpenVINO {runtime_value:.2f} {unit}, {RUNTIMES['native']} {baseline:.2f} {unit} "
          f"({baseline / runtime_value:.1f}x)", flush=True)


MEMORY_PROBE = textwrap.dedent("""
    import json, sys
    import numpy as np
    from merlin2_sailor.anchoring.service import AnchoringService
    from merlin2_sailor.anchoring.settings import default_settings
    from merlin2_sailor.inference.settings import PRECISIONS, InferenceSettings
    import dataclasses
    base = default_settings()
    matcher = dataclasses.replace(base.matcher, name="network", inference=InferenceSettings(runtime=sys.argv[1]))
    persistence = dataclasses.replace(base.persistence, knowledge_base="", state_folder="")
    service = AnchoringService(dataclasses.replace(base, matcher=matcher, persistence=persistence))
    crops = [np.random.default_rng(k).integers(0, 255, (120, 90, 3), np.uint8) for k in range(8)]
    service.embedder.embed(crops)
    rss = next(int(line.split()[1]) for line in open("/proc/self/status") if line.startswith("VmRSS:"))
    print(json.dumps({"rss_mb": rss / 1024.0, "torch": "torch" in sys.modules}))
""")


def service_memory(runtime: str) -> dict[str, float]:
    completed = subprocess.run([sys.executable, "-c", MEMORY_PROBE, runtime], capture_output=True, text=True,
                               timeout=600, check=True)
    return json.loads(completed.stdout.strip().splitlines()[-1])


def measure_threads(result: BenchmarkResult, rows: list[list[object]], threads: int, photos: list[np.ndarray],
                    crops: list[np.ndarray], batch_sizes: tuple[int, ...], repeats: int) -> None:
    """Every network on both runtimes with ``threads`` threads, in float32 and (OpenVINO) in the
    device's fastest precision; targets apply to two threads (two cores)."""
    two_cores = threads == 2
    embedding_target = {"target": "<= 5 ms/crop, >= 2.5x torch", "target_value": 5.0} if two_cores else {}
    for precision in PRECISIONS:
        embedders = {runtime: {size: CropEmbedder(EmbeddingConfig(
            batch_size=size, inference=settings(runtime, threads, precision))) for size in batch_sizes}
            for runtime in RUNTIMES}
        for size in batch_sizes if precision == "f32" else (EmbeddingConfig().batch_size,):
            compare(result, rows, f"embedding, batch {size}, {threads} thread(s), {precision}", "ms/crop",
                    lambda runtime, s=size, e=embedders: median_seconds(lambda: e[runtime][s].embed(crops), repeats)
                    / len(crops) * 1e3, **embedding_target)
    # The detector in every precision it has, int8 (its default) included; OpenCV DNN, float32, is the baseline.
    detector_target = {"target": "<= 25 ms/frame, >= 2x OpenCV DNN", "target_value": 25.0} if two_cores else {}
    for precision in DETECTOR_PRECISIONS:
        detectors = {runtime: create_detector("ssd_mobilenet", {"inference": settings(runtime, threads, precision)})
                     for runtime in RUNTIMES}
        compare(result, rows, f"detector, {threads} thread(s), {precision}", "ms/frame",
                lambda runtime, d=detectors: median_seconds(lambda: [d[runtime].detect(p) for p in photos], repeats)
                / len(photos) * 1e3, **detector_target)
    matchers = {runtime: create_matcher(MatcherSettings(name="network", inference=settings(runtime, threads, "f32")))
                for runtime in RUNTIMES}
    for pairs in (20, 200):
        features = frame_pairs(pairs, matchers["native"].metadata.feature_dimension)
        compare(result, rows, f"matching network, {pairs} pairs, {threads} thread(s), f32", "ms/call",
                lambda runtime, f=features: median_seconds(lambda: matchers[runtime].score_pairs(f), repeats * 3)
                * 1e3)


def run(quick: bool = False) -> BenchmarkResult:
    repeats = 3 if quick else 7
    photos = load_photos()
    crops = crops_of(photos, 16)
    thread_counts = (2,) if quick else (2, 1)
    batch_sizes = (1, 4, 16) if quick else (1, 2, 4, 8, 16)
    result = BenchmarkResult(
        "inference", "Inference runtime: OpenVINO vs torch / OpenCV DNN",
        f"Each network on each runtime, same inputs, median of {repeats} passes after a warm-up: crop embedding "
        f"(16 crops of 40-300 px from the darknet photos, whole path incl. resize and crop descriptor), the "
        f"SSD-MobileNet detector ({len(photos)} photos at 640x480), the matching network's heads (a frame's pairs). "
        "Threads as given per row. Memory: the anchoring service with the learned matcher, each runtime in a "
        "fresh process.",
        parameters={"repeats": repeats, "threads": list(thread_counts), "batch_sizes": list(batch_sizes)},
    )
    rows: list[list[object]] = []
    for threads in thread_counts:
        measure_threads(result, rows, threads, photos, crops, batch_sizes, repeats)
    memory = {runtime: service_memory(runtime) for runtime in RUNTIMES}
    result.figure("anchoring service RSS with the learned matcher", memory["openvino"]["rss_mb"], "MB",
                  baseline=memory["native"]["rss_mb"], baseline_name="torch", target="below torch's",
                  met=memory["openvino"]["rss_mb"] < memory["native"]["rss_mb"])
    openvino_mb, torch_mb = memory["openvino"]["rss_mb"], memory["native"]["rss_mb"]
    rows.append(["anchoring service RSS (MB)", round(openvino_mb, 1), round(torch_mb, 1),
                 round(torch_mb / openvino_mb, 2)])
    print(f"  anchoring service RSS: OpenVINO {memory['openvino']['rss_mb']:.0f} MB (torch imported: "
          f"{memory['openvino']['torch']}), torch {memory['native']['rss_mb']:.0f} MB", flush=True)
    result.tables.append(Table("OpenVINO against torch / OpenCV DNN", ["measure", "OpenVINO", "baseline", "speed-up"],
                               rows))
    result.tables.append(Table("torch imported by the anchoring service", ["runtime", "torch imported"],
                               [[runtime, memory[runtime]["torch"]] for runtime in RUNTIMES]))
    return result


def main() -> int:
    return script.main(run, __doc__)


if __name__ == "__main__":
    raise SystemExit(main())
