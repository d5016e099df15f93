"""``sailor demo``: the mission demo in the simulated house, start to report, in one command.

It runs the ``demo`` launch file (world, percept generator, anchoring, knowledge base, behaviors
and the mission_demo node, each its own process) with its data in one output folder, which it
empties first so that every run starts from a robot that knows nothing; then it prints the
report's summary. Exit status: 0 when the demo succeeded and every node ended cleanly, 1
otherwise, 2 for an error before the start (an output folder that is not a demo's, say).
"""

from __future__ import annotations

import argparse
import os
import shutil
from pathlib import Path

from merlin2_sailor.cli import launch_command
from merlin2_sailor.errors import ConfigurationError

DEFAULT_OUTPUT = Path("reports") / "demo"
DATA_VARIABLE = "SAILOR_DATA"  # what launch/demo.yaml reads its folders from
#: What a demo run leaves in its output folder: the only entries it removes before a new run.
DEMO_ENTRIES = ("report", "anchoring", "knowledge.db", "ground_truth.json")


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "demo",
        help="run the mission demo in the simulated house and write its report",
        description=(
            "Explore a simulated house, anchor what the camera sees, then find the red mug after "
            "it was moved behind the robot's back; every part runs as its own ROS 2 process. Writes "
            "OUTPUT/report/ (summary.md, scorecard.json, map.png, frames/, knowledge.pddl, "
            "account.log) and prints the summary. Takes about two minutes."
        ),
    )
    parser.add_argument(
        "--output", type=Path, default=DEFAULT_OUTPUT, metavar="FOLDER",
        help=f"where the run's data and report go (default: {DEFAULT_OUTPUT}); emptied of a previous "
             "demo's files first",
    )
    launch_command.add_grace_period_argument(parser)
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    output = prepare_output(arguments.output)
    os.environ[DATA_VARIABLE] = str(output)
    # The demo is self-contained: keep its DDS traffic on this machine unless told otherwise.
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    status = launch_command.run(argparse.Namespace(
        launch_file="demo", duration=None, grace_period=arguments.grace_period))
    summary = output / "report" / "summary.md"
    print()
    if summary.is_file():
        print(summary.read_text(encoding="utf-8"), flush=True)
    else:
        print(f"No report was written ({summary} is missing); the log above says why.", flush=True)
    return status


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
