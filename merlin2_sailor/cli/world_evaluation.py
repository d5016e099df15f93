"""``sailor evaluate --world FILE``: the matching functions compared on tours of a simulated house.

Pair metrics score the matching function on pairs one at a time; a user asks whether each
object of a house ends up anchored once, under one symbol. This drives the robot round a world
file's house (every waypoint, a look around at each, then back through the house: see
:mod:`merlin2_sailor_demos.identity.tour`), without ROS, feeding one anchoring core per matcher
the same frames, and prints what the demo's scorecard counts for each: duplicate anchors and
identity switches, plus the objects given two symbols and the symbols given two objects
(:mod:`merlin2_sailor_demos.identity.tour_evaluation`). Both matchers and the core are built from
the anchoring node's settings (``--launch demo`` takes the demo's), and the tour's percept
generator sees as far as the anchoring layer expects it to (``visible_range``).
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

from merlin2_sailor.errors import ConfigurationError


def add_world_arguments(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group(
        "tour of a simulated house", "instead of scoring pairs, tour a world with each matcher")
    group.add_argument("--world", default="", metavar="FILE",
                       help="world file to tour (a path, or one shipped in config/, e.g. worlds/house.yaml); "
                            "use --launch demo for the demo's anchoring settings")
    group.add_argument("--world-seeds", default="0", metavar="N[,N...]",
                       help="world seeds (odometry, depth noise, detector mistakes), one tour each (default 0)")


def run_world(arguments: argparse.Namespace, matchers: Sequence[str]) -> int:
    """Tour ``arguments.world`` once per seed with each of ``matchers`` (registry names)."""
    from merlin2_sailor.anchoring.matcher_registry import create_matching
    from merlin2_sailor.cli.anchoring_settings import settings_from_arguments
    from merlin2_sailor.resources import config_path
    from merlin2_sailor_demos.identity.tour import TourConfig
    from merlin2_sailor_demos.identity.tour_evaluation import MatcherSetup, evaluate_tour, format_tour_table
    from merlin2_sailor_demos.world import load_world

    try:
        seeds = [int(seed) for seed in arguments.world_seeds.split(",")]
    except ValueError:
        raise ConfigurationError(f"--world-seeds {arguments.world_seeds!r}: write seeds as N or N,N,...") from None
    started = time.perf_counter()
    settings = settings_from_arguments(arguments, {"weights": arguments.weights} if arguments.weights else None)
    path = config_path(arguments.world, "worlds/house.yaml")
    description = load_world(path)
    tour = TourConfig(maximum_depth=settings.core.visibility.frustum.far)

    def contender(name: str):  # type: ignore[no-untyped-def]
        def build() -> MatcherSetup:
            matcher, embedder = create_matching(replace(settings.matcher, name=name))
            return MatcherSetup(matcher, embedder)
        return build

    contenders = {name: contender(name) for name in matchers}
    totals = {name: {"duplicates": 0, "identity_switches": 0, "split_objects": 0, "merged_symbols": 0}
              for name in contenders}
    runs = []
    for seed in seeds:
        scores = evaluate_tour(description, contenders, seed=seed, tour=tour, config=settings.core,
                               track_period=settings.timing.track_period)
        print(f"{path.name}, world seed {seed}")
        print(format_tour_table(scores), flush=True)
        print()
        for name, result in scores.items():
            figures = {"duplicates": result.duplicates, "identity_switches": result.switches,
                       "split_objects": len(result.split_objects), "merged_symbols": len(result.merged_symbols)}
            for key, value in figures.items():
                totals[name][key] += value
            runs.append({"seed": seed, "matcher": name, **figures, "scorecard": result.scorecard.to_dict(),
                         "split": result.split_objects, "merged": result.merged_symbols})
    if len(seeds) > 1:
        print(f"over {len(seeds)} seeds: " + "; ".join(
            f"{name} {total['duplicates']} duplicates, {total['identity_switches']} identity switches"
            for name, total in totals.items()))
    seconds = time.perf_counter() - started
    print(f"toured in {seconds:.1f} s")
    if arguments.output:
        folder = Path(arguments.output)
        folder.mkdir(parents=True, exist_ok=True)
        report = {"world": str(path), "seeds": seeds, "totals": totals, "runs": runs, "seconds": round(seconds, 1)}
        (folder / "tour.json").write_text(json.dumps(report, indent=2, default=str) + "\n")
        print(f"wrote {folder / 'tour.json'}")
    return 0
