"""``sailor bench``: run the benchmark suite of the source checkout (bench/suite.py).

The benchmarks, their harness and the suite that runs them all live in bench/, which is part of
the source checkout and not of the installed package. This command only finds that folder and
runs ``python bench/suite.py`` with the options it was given, so the package never imports the
checkout's code (it treats bench/ as data, as it treats config/). ``sailor bench --help`` is the
suite's own help, with the list of benchmarks. From a pip install, it says where the suite is.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.resources import share_directory

SUITE = "suite.py"
#: Exit code of a run interrupted with Ctrl-C, as a shell reports it.
INTERRUPTED = 130


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    # Every argument, --help included, belongs to bench/suite.py: no prefix character is ours, so
    # argparse passes them all on untouched instead of parsing them here.
    parser = subparsers.add_parser(
        "bench", help="run the benchmarks and write a report (Markdown, JSON, PNG plots); --help lists them",
        add_help=False, prefix_chars="\0",
    )
    parser.add_argument("suite_arguments", nargs=argparse.REMAINDER)
    parser.set_defaults(run=run)


def bench_directory() -> Path:
    """bench/ of the source checkout this package runs from, else of the current folder."""
    candidates = [Path.cwd() / "bench"]
    try:
        candidates.insert(0, share_directory() / "bench")
    except ConfigurationError:
        pass
    for folder in candidates:
        if (folder / SUITE).is_file():
            return folder
    raise ConfigurationError(
        f"the benchmarks are not installed with the package (no bench/{SUITE} in "
        f"{' or '.join(map(str, candidates))}); run sailor bench from a source checkout set up with scripts/setup.sh")


def run(arguments: argparse.Namespace) -> int:
    command = [sys.executable, str(bench_directory() / SUITE), *arguments.suite_arguments]
    process = subprocess.Popen(command, stdin=subprocess.DEVNULL)
    try:
        return process.wait()
    except KeyboardInterrupt:  # Ctrl-C reached the suite too: let it stop the benchmark it runs
        try:
            process.wait(timeout=60.0)
        except subprocess.TimeoutExpired:
            process.terminate()
            process.wait()
        return INTERRUPTED
