"""Duplicates and identity switches of the matching functions on tours of houses, without ROS.

Each house is toured once per seed (every waypoint, a look around at each, then back through the
house: merlin2_sailor_demos.identity.tour) with the real perceptual layer (renderer, ground-truth
detector with its noise, ByteTrack, percept generator) and one anchoring core per matcher, fed the
same frames (merlin2_sailor_demos.identity.tour_evaluation). Houses: the demo's
(config/worlds/house.yaml) and held-out generated houses (the house source's ``test`` split,
never used to train or choose the shipped weights). Matchers: the rules at the demo's tolerance
(launch/demo.yaml: rules_maximum_sigma 0.3) and the shipped network. Counted as the demo's
scorecard counts them: duplicate anchors at the end, identity switches over the tour, and from
each percept's true object, the objects given two surviving symbols (split) and the symbols given
two objects (merged). Nothing is asserted; it prints figures.

Run: python bench/bench_network_houses.py [--quick] [--json PATH] [--weights PATH]
"""

# ruff: noqa: E402 - the thread limits must be set before NumPy and torch are imported
from __future__ import annotations

import os

for variable in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(variable, "2")

from pathlib import Path

from harness import script
from harness.results import BenchmarkResult, Table

from merlin2_sailor.anchoring.matching_network import NetworkMatcher, load_network
from merlin2_sailor.anchoring.rule_matcher import RuleMatcher, RuleMatcherConfig
from merlin2_sailor.models import DEFAULT_BACKBONE, default_weights_path
from merlin2_sailor.perception.embedding import CropEmbedder
from merlin2_sailor_demos.identity.house_source import HouseSource
from merlin2_sailor_demos.identity.tour import TourConfig
from merlin2_sailor_demos.identity.tour_evaluation import MatcherSetup, evaluate_tour
from merlin2_sailor_demos.world import load_world

HOUSE_FILE = Path(__file__).resolve().parent.parent / "config" / "worlds" / "house.yaml"
DEMO_RULES = RuleMatcherConfig(maximum_sigma=0.3)
FIGURES = ("duplicates", "switches", "split", "merged")


def run(quick: bool = False, weights: str = "") -> BenchmarkResult:
    network = load_network(weights or default_weights_path(), DEFAULT_BACKBONE)
    embedder = CropEmbedder()
    contenders = {
        "rules": lambda: MatcherSetup(RuleMatcher(DEMO_RULES)),
        "network": lambda: MatcherSetup(NetworkMatcher(network), embedder),
    }
    source = HouseSource()
    houses = [("demo house", load_world(HOUSE_FILE), seed) for seed in ((0,) if quick else (0, 1, 2))]
    for index in (range(2) if quick else range(6)):
        description, seed = source.house("test", index)
        houses.append((f"test house {index}", description, seed))
    result = BenchmarkResult(
        "network_houses", "Matching functions on tours of houses: duplicates and identity switches",
        __doc__.split("\n\n")[1].replace("\n", " "),
        parameters={"weights": str(weights or default_weights_path()), "tours": len(houses)},
    )
    rows, totals = [], {name: dict.fromkeys(FIGURES, 0) for name in contenders}
    for label, description, seed in houses:
        scores = evaluate_tour(description, contenders, seed=seed, tour=TourConfig())
        for name, score in scores.items():
            figures = {"duplicates": score.duplicates, "switches": score.switches,
                       "split": len(score.split_objects), "merged": len(score.merged_symbols)}
            for key, value in figures.items():
                totals[name][key] += value
            rows.append([label, seed, name, f"{score.scorecard.anchored} / {score.scorecard.objects}",
                         *figures.values()])
        print(f"  {label} (seed {seed}): " + "; ".join(
            f"{name} {s.duplicates} duplicates, {s.switches} switches" for name, s in scores.items()), flush=True)
    for key in FIGURES:
        result.figure(f"{key}, all tours", totals["network"][key], "count", baseline=totals["rules"][key],
                      baseline_name="rules")
    result.tables.append(Table("per tour", ["house", "seed", "matcher", "anchored", *FIGURES], rows))
    return result


def main() -> int:
    def extend(parser) -> None:  # noqa: ANN001
        parser.add_argument("--weights", default="", help="weights file (default: the shipped ones)")

    return script.main(run, __doc__, extend=extend)


if __name__ == "__main__":
    raise SystemExit(main())
