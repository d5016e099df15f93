"""``sailor evaluate``: the paper's pair metrics and anchoring-level identity metrics.

On the pairs of a split of the generated source (default: the held-out ``test`` scenes, never
used in training or model selection), the matching network and the hand-tuned rule matcher are
scored side by side: the confusion matrix and accuracy / precision / recall / F1 over every pair
and over the look-alike pairs (same class, near). Then each scene is replayed through the whole
anchoring layer with each matcher and the symbols are scored against the ground truth (ID
switches, IDF1, via motmetrics). Every pair is also scored at every threshold (the F1 at the
anchoring layer's threshold beside the best one: how much of a shortfall is where the cut is,
not what the scores tell apart). Text on stdout; with ``--output``, a confusion-matrix PNG, pair
F1 against the threshold (PNG) and a JSON of every number. ``--source`` evaluates on a public
data set's split instead (see ``sailor train``). ``--world FILE`` tours a simulated house with each matcher instead
(:mod:`.world_evaluation`): duplicate anchors and identity switches against the world's truth.
Both matchers and the anchoring layer are built from the anchoring node's settings
(config/anchoring.yaml; ``--launch``, ``--params``, ``--set`` as for ``sailor replay``), by name
through the matcher registry, so the figures are the deployed system's.
"""

from __future__ import annotations

import argparse
import json
import time
from dataclasses import asdict, replace
from pathlib import Path
from typing import TYPE_CHECKING

from merlin2_sailor.cli.anchoring_settings import add_settings_arguments, settings_from_arguments
from merlin2_sailor.cli.train_command import DEFAULT_SCENES, DEFAULT_SOURCE, SOURCE_HELP, embedding_cache, pair_source
from merlin2_sailor.cli.world_evaluation import add_world_arguments, run_world

if TYPE_CHECKING:
    from merlin2_sailor.training.metrics import ThresholdSweep

#: The matchers compared, each built from the same settings, by name.
COMPARED_MATCHERS = ("network", "rules")


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "evaluate", help="evaluate matching weights (pairs and anchoring) against the rule matcher",
        description="Evaluate a matching network on a split of the generated source: the paper's "
                    "confusion matrix and metrics table, and identity metrics of the whole anchoring layer.",
    )
    parser.add_argument("--weights", default="", metavar="PATH",
                        help="weights file (default: the parameter files' weights, else the ones shipped in "
                             "merlin2_sailor/models)")
    parser.add_argument("--source", default=DEFAULT_SOURCE, metavar="SPEC", help=SOURCE_HELP)
    parser.add_argument("--split", default="test",
                        help="split to evaluate on (default test; a public data set also has 'all')")
    parser.add_argument("--scenes", type=int, default=None, metavar="N",
                        help="scenes of the split (default 10 houses, 30 generated scenes)")
    parser.add_argument("--first", type=int, default=0, metavar="I", help="first scene index (default 0)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the generated source (default 0)")
    parser.add_argument("--output", default="", metavar="DIR", help="write confusion.png and metrics.json here")
    parser.add_argument("--no-identity", action="store_true", help="skip the anchoring-level metrics")
    parser.add_argument("--cache", default=None, metavar="DIR",
                        help="embedding cache folder (default $SAILOR_CACHE or ~/.cache/merlin2_sailor/embeddings)")
    parser.add_argument("--no-cache", action="store_true", help="keep embeddings in memory only")
    parser.add_argument("--darknet", default="", metavar="DIR", help="darknet photo folder")
    parser.add_argument("--no-darknet", action="store_true", help="use scikit-image's photos only")
    add_world_arguments(parser)
    add_settings_arguments(parser)
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    if arguments.world:
        return run_world(arguments, COMPARED_MATCHERS)
    if arguments.scenes is None:
        arguments.scenes = DEFAULT_SCENES.get(arguments.source, DEFAULT_SCENES["generated"])[2]
    from merlin2_sailor.anchoring.matcher_registry import create_matcher
    from merlin2_sailor.anchoring.settings import parameter_values
    from merlin2_sailor.models import default_weights_path
    from merlin2_sailor.training.generated_dataset import GeneratedPairSet
    from merlin2_sailor.training.identity_evaluation import evaluate_identities, format_identity_table
    from merlin2_sailor.training.metrics import format_confusion, format_sweeps, format_table
    from merlin2_sailor.training.pair_dataset import PairDatasetConfig
    from merlin2_sailor.training.pair_scoring import evaluate_pairs
    from merlin2_sailor.training.plots import plot_confusions, plot_threshold_sweeps

    started = time.perf_counter()
    # The anchoring node's settings (the same parameter files), offline; each matcher compared is
    # built from them by name, as the node builds its own.
    settings = settings_from_arguments(arguments, {"weights": arguments.weights} if arguments.weights else None)
    weights = Path(settings.matcher.weights).expanduser() if settings.matcher.weights else default_weights_path()
    built = {name: create_matcher(replace(settings.matcher, name=name)) for name in COMPARED_MATCHERS}
    source = pair_source(arguments)
    pair_set = GeneratedPairSet(source, arguments.split, arguments.scenes, PairDatasetConfig(), arguments.first)
    # The crops' features are cached by backbone; percepts carry them, so no embedder is built.
    cache = embedding_cache(arguments, settings.matcher.backbone)
    pair_set.embed(cache)

    # Matchers are stateless: each scene gets a fresh Anchoring around the same one.
    matchers = {name: (lambda matcher=matcher: matcher) for name, matcher in built.items()}
    threshold = settings.core.match_threshold
    pairs = {name: evaluate_pairs(factory(), pair_set.chunks(), cache, threshold) for name, factory in matchers.items()}
    table = {name: result.all_pairs for name, result in pairs.items()}
    table.update({f"{name} look-alike": result.look_alike for name, result in pairs.items()})
    table.update({f"{name} partial view": result.partial for name, result in pairs.items()})
    table.update({f"{name} searched": result.searched for name, result in pairs.items() if result.searched.total})
    table.update({f"{name} replaced": result.replaced for name, result in pairs.items() if result.replaced.total})
    table.update({f"{name} as run": result.as_run for name, result in pairs.items() if built[name].uses_appearance})
    print(f"weights {weights}; split {arguments.split!r}, scenes {arguments.first}.."
          f"{arguments.first + arguments.scenes - 1}, seed {arguments.seed}, threshold {threshold:g}\n")
    print("pairs (Algorithm 3, every pair; look-alike = same class, nearer than 1 m; partial view = either "
          "side cut by the image's edge or an occluder; searched = extra pairs measured from a searched disc, "
          "replaced = extra pairs of another object of the class where the anchor stood: only appearance tells; "
          "as run = every pair again, a partial percept scored without its look, as the anchoring layer does, "
          "so by the rules)")
    print(format_table(table))
    print()
    sweeps = {name: result.all_pairs_sweep for name, result in pairs.items()}
    sweeps.update({f"{name} as run": result.as_run_sweep for name, result in pairs.items()
                   if built[name].uses_appearance})
    print("every pair of Algorithm 3 again, at every threshold: how much of the F1 is where the cut is")
    print(format_sweeps(sweeps, threshold))
    print()
    for name, result in pairs.items():
        print(format_confusion(name, result.all_pairs))
        print()

    identities = {}
    if not arguments.no_identity:
        identities = {
            name: evaluate_identities(factory, pair_set.scenes(), cache, settings.core)
            for name, factory in matchers.items()
        }
        print("anchoring (the whole layer replayed over each scene; percepts vs ground-truth instances)")
        print(format_identity_table(identities))
    seconds = time.perf_counter() - started
    print(f"\nevaluated in {seconds:.1f} s")

    if arguments.output:
        folder = Path(arguments.output)
        folder.mkdir(parents=True, exist_ok=True)
        image = plot_confusions(folder / "confusion.png", table)
        sweep_image = plot_threshold_sweeps(folder / "threshold_sweep.png", sweeps, threshold)
        report = {
            "weights": str(weights),
            "source": arguments.source,
            "split": arguments.split, "scenes": arguments.scenes, "first": arguments.first, "seed": arguments.seed,
            "pairs": {name: counts.as_dict() for name, counts in table.items()},
            "threshold_sweep": {name: _sweep_summary(sweep, threshold) for name, sweep in sweeps.items()},
            "anchoring": {name: metrics.as_dict() for name, metrics in identities.items()},
            "source_config": asdict(source.config),
            "anchoring_settings": parameter_values(settings),
            "seconds": round(seconds, 1),
        }
        (folder / "metrics.json").write_text(json.dumps(report, indent=2, default=str) + "\n")
        print(f"wrote {image}, {sweep_image} and {folder / 'metrics.json'}")
    return 0


def _sweep_summary(sweep: ThresholdSweep, threshold: float) -> dict:
    """A sweep in metrics.json: the counts at the anchoring threshold and at the best one."""
    best_threshold, best = sweep.best()
    return {"threshold": threshold, "at_threshold": sweep.at(threshold).as_dict(),
            "best_threshold": best_threshold, "best": best.as_dict()}
