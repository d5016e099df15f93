"""``sailor demo``: the mission demo in the simulated house, start to report, in one command.

It runs the ``demo`` launch file (world, percept generator, anchoring, knowledge base, behaviors
and the mission_demo node, each its own process) with its data in one output folder, which it
empties first so that every run starts from a robot that knows nothing; then it prints the
report's summary. Exit status: 0 when the demo succeeded and every node ended cleanly, 1
otherwise, 2 for an error before the start (an output folder that is not a demo's, say).

With ``--scenario NAME`` or ``--all-scenarios`` it runs scenarios of the suite
(``config/worlds/scenarios/``, see ``--list-scenarios``) instead, for each seed of ``--seeds``:
each run in its own folder ``OUTPUT/runs/<scenario>-seed<N>-<matcher>/`` and DDS domain, within
a deadline, judged against the world's ground truth; a progress line per run, then the table
(also written as ``OUTPUT/scenarios.md`` and ``OUTPUT/scenarios.json``). Exit status 0 when every
run was right.

With ``--soak N`` it runs N runs of the default demo and the scenarios in turn, each with the next
seed, to find what happens only now and then: the table, then the soak's summary (runs, right,
wrong, hangs, crashes, lost results recovered, steps cancelled at their deadline, the slowest
run; also ``OUTPUT/soak.md`` and ``OUTPUT/soak.json``). Exit status 0 when no run hung or crashed.
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import threading
from pathlib import Path

from merlin2_sailor.cli import launch_command
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.launcher.recording import add_record_arguments, with_recorder

DEFAULT_OUTPUT = Path("reports") / "demo"
#: What a demo run leaves in its output folder: the only entries it removes before a new run.
DEMO_ENTRIES = ("report", "anchoring", "knowledge.db", "ground_truth.json", "runs", "scenarios.md",
                "scenarios.json", "soak.md", "soak.json")
MATCHERS = ("rules", "network")
#: Seconds a scenario run may take before it is stopped and counted as a hang (one takes 1-3 min).
DEFAULT_DEADLINE = 420.0


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "demo",
        help="run the mission demo in the simulated house (or its scenario suite) and write its report",
        description=(
            "Explore a simulated house, anchor what the camera sees, then find the red mug after "
            "it was moved behind the robot's back; every part runs as its own ROS 2 process. Writes "
            "OUTPUT/report/ (summary.md, scorecard.json, map.png, frames/, knowledge.pddl, "
            "account.log) and prints the summary. Takes about two minutes. With --scenario or "
            "--all-scenarios, runs scenarios of the suite (moved look-alikes, removed and swapped "
            "objects, ...) and prints a table of their outcomes against the ground truth."
        ),
    )
    parser.add_argument(
        "--output", type=Path, default=DEFAULT_OUTPUT, metavar="FOLDER",
        help=f"where the run's data and report go (default: {DEFAULT_OUTPUT}); emptied of a previous "
             "demo's files first",
    )
    which = parser.add_mutually_exclusive_group()
    which.add_argument("--scenario", action="append", metavar="NAME",
                       help="run this scenario of the suite (repeatable; see --list-scenarios)")
    which.add_argument("--all-scenarios", action="store_true", help="run every scenario of the suite")
    which.add_argument("--list-scenarios", action="store_true",
                       help="list the scenarios with what each shows, and exit")
    which.add_argument("--soak", type=_run_count, default=None, metavar="N",
                       help="run N runs, the default demo and every scenario in turn, each with the next seed "
                            "(from --seed's), and report hangs, wrong identities and the slowest run")
    seeds = parser.add_mutually_exclusive_group()
    seeds.add_argument("--seed", type=_seed, default=None, metavar="N",
                       help="seed of the world's randomness (odometry, depth noise, detector; default: "
                            "config/world.yaml's)")
    seeds.add_argument("--seeds", type=_seed_list, default=None, metavar="N,N,...",
                       help="run each scenario once per seed, e.g. 0,1,2")
    parser.add_argument("--matcher", choices=MATCHERS, default=None,
                        help="the anchoring node's matching function (default: config/anchoring.yaml's)")
    parser.add_argument("--deadline", type=float, default=DEFAULT_DEADLINE, metavar="SECONDS",
                        help=f"stop a scenario run after this long and count a hang (default {DEFAULT_DEADLINE:g})")
    launch_command.add_grace_period_argument(parser)
    add_record_arguments(parser)
    parser.set_defaults(run=run)


def _seed(text: str) -> int:
    try:
        seed = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"a seed is an integer, got {text!r}") from None
    if not 0 <= seed < 2**31:
        raise argparse.ArgumentTypeError(f"a seed is an integer from 0 to 2^31 - 1, got {seed}")
    return seed


def _run_count(text: str) -> int:
    try:
        count = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"a number of runs must be a whole number, got {text!r}") from None
    if count < 1:
        raise argparse.ArgumentTypeError(f"a number of runs must be at least 1, got {count}")
    return count


def _seed_list(text: str) -> list[int]:
    seeds = [_seed(item.strip()) for item in text.split(",") if item.strip()]
    if not seeds:
        raise argparse.ArgumentTypeError(f"give seeds separated by commas, e.g. 0,1,2, got {text!r}")
    return seeds


def run(arguments: argparse.Namespace) -> int:
    if arguments.record and (arguments.scenario or arguments.all_scenarios or arguments.soak):
        raise ConfigurationError("--record records the default demo (or one launch: sailor launch NAME --record)")
    if arguments.list_scenarios:
        return list_scenarios()
    if arguments.scenario or arguments.all_scenarios or arguments.soak:
        return run_scenarios(arguments)
    if arguments.seeds is not None:
        raise ConfigurationError("--seeds runs scenarios: give --scenario NAME or --all-scenarios too")
    return run_default(arguments)


def list_scenarios() -> int:
    from merlin2_sailor_demos.scenarios import all_scenarios

    entries = all_scenarios()
    width = max(len(entry.name) for entry in entries)
    for entry in entries:
        print(f"{entry.name:<{width}}  {entry.description}")
    return 0


def run_default(arguments: argparse.Namespace) -> int:
    """The demo as ``make demo`` runs it (the seed and matcher overridden when given)."""
    from merlin2_sailor_demos.scenario_runner import RunOptions, demo_launch, launch

    output = prepare_output(arguments.output)
    options = RunOptions(seed=arguments.seed, matcher=arguments.matcher, grace_period=arguments.grace_period)
    spec = demo_launch(output, None, options)
    if arguments.record:
        spec = with_recorder(spec, arguments.record, arguments.record_storage)
    result, _ = launch(spec, None, arguments.grace_period, None)
    print(result.summary(), flush=True)
    if arguments.record:
        print(f"Recorded to {arguments.record}; replay it with: sailor replay bag {arguments.record} --launch demo",
              flush=True)
    summary = output / "report" / "summary.md"
    print()
    if summary.is_file():
        print(summary.read_text(encoding="utf-8"), flush=True)
    else:
        print(f"No report was written ({summary} is missing); the log above says why.", flush=True)
    return 0 if result.succeeded else 1


def run_scenarios(arguments: argparse.Namespace) -> int:
    """Every requested scenario once per seed (or the soak's runs), one after another, then the
    table (and the soak's summary)."""
    from merlin2_sailor.anchoring.matcher_registry import MatcherSettings
    from merlin2_sailor_demos.dds_domains import DOMAINS, claimed_domain
    from merlin2_sailor_demos.report.scenario_table import to_markdown, to_text, write_table
    from merlin2_sailor_demos.report.soak_summary import SoakSummary, write_soak
    from merlin2_sailor_demos.scenario_runner import (
        ANCHORING_NODE,
        WORLD_NODE,
        RunOptions,
        demo_launch,
        effective_parameter,
        run_scenario,
    )
    from merlin2_sailor_demos.scenarios import all_scenarios, find_scenario

    entries = all_scenarios() if arguments.all_scenarios or arguments.soak else [
        find_scenario(name) for name in arguments.scenario]
    if arguments.soak and arguments.seeds is not None:
        raise ConfigurationError("--soak gives each run the next seed: give the first with --seed, not --seeds")
    if arguments.deadline <= 0:
        raise ConfigurationError(f"--deadline must be positive, got {arguments.deadline:g}")
    output = prepare_output(arguments.output)
    configured = demo_launch(output, None, RunOptions())  # what the launch's own configuration says
    matcher = arguments.matcher or str(effective_parameter(configured, ANCHORING_NODE, "matcher")
                                       or MatcherSettings().name)
    configured_seed = int(effective_parameter(configured, WORLD_NODE, "seed") or 0)
    first_seed = arguments.seed if arguments.seed is not None else configured_seed
    if arguments.soak:
        plan = [(entries[index % len(entries)], first_seed + index) for index in range(arguments.soak)]
    else:
        plan = [(entry, seed) for entry in entries for seed in (arguments.seeds or [first_seed])]
    stop = threading.Event()
    runs = []
    for index, (entry, seed) in enumerate(plan):
        folder = output / "runs" / f"{entry.name}-seed{seed}-{matcher}"
        with claimed_domain(DOMAINS, os.getpid() + index) as domain:
            options = RunOptions(seed=seed, matcher=arguments.matcher, deadline=arguments.deadline,
                                 grace_period=arguments.grace_period, domain=domain)
            print(f"[{index + 1}/{len(plan)}] {entry.name} seed {seed} {matcher}: running in {folder} "
                  f"(ROS_DOMAIN_ID {domain})", flush=True)
            done = run_scenario(entry, folder, options, matcher, echo=sys.stdout if len(plan) == 1 else None,
                                stop=stop)
        runs.append(done)
        print(done.progress_line(index + 1, len(plan)), flush=True)
        if stop.is_set():
            print("stopped by the user; the table holds the runs so far", flush=True)
            break
    markdown, data = write_table(output, runs)
    print()
    print(to_text(runs), end="", flush=True)
    print(f"\nTable written to {markdown} and {data}", flush=True)
    if arguments.soak:
        summary = SoakSummary.of(runs)
        soak_markdown, soak_data = write_soak(output, summary, to_markdown(runs))
        print(f"\nSoak of {len(runs)} run(s):\n{summary.to_text()}Written to {soak_markdown} and {soak_data}",
              flush=True)
        return 0 if len(runs) == len(plan) and summary.hangs == 0 and summary.crashes == 0 else 1
    return 0 if len(runs) == len(plan) and all(done.right for done in runs) else 1


def prepare_output(folder: Path) -> Path:
    """The output folder, absolute and free of a previous run's files; refuses a stranger's folder."""
    folder = folder.expanduser().resolve()
    if folder.exists() and not folder.is_dir():
        raise ConfigurationError(f"the demo's output {folder} exists and is not a folder")
    if folder.is_dir():
        strangers = sorted(entry.name for entry in folder.iterdir() if entry.name not in DEMO_ENTRIES)
        if strangers:
            raise ConfigurationError(
                f"{folder} holds files a demo did not write ({', '.join(strangers[:5])}); "
                "choose an empty or new folder with --output"
            )
        for name in DEMO_ENTRIES:
            entry = folder / name
            if entry.is_dir():
                shutil.rmtree(entry)
            elif entry.exists():
                entry.unlink()
    folder.mkdir(parents=True, exist_ok=True)
    return folder
