"""The command line every benchmark script shares: ``--quick``, ``--json PATH``; prints its figures.

``python bench/bench_x.py`` prints as it always did; ``sailor bench`` runs the same script with
``--json`` and reads the structured result back, each benchmark in a process of its own (thread
limits set before NumPy loads, a fresh heap for memory figures, no state shared between them).
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

from harness.machine import summary
from harness.results import BenchmarkResult, json_safe


class CannotRun(RuntimeError):
    """What a benchmark needs is missing (its message says how to get it): one line, exit code 2."""


def parser(description: str) -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(description=description.strip().splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the short form (smaller sizes, shorter runs)")
    parser.add_argument("--json", type=Path, default=None, metavar="PATH", help="also write the result as JSON")
    return parser


def main(
    run: Callable[..., BenchmarkResult],
    description: str,
    argv: Sequence[str] | None = None,
    extend: Callable[[argparse.ArgumentParser], None] | None = None,
) -> int:
    """Parse the arguments, print the machine, run, print the figures, write the JSON if asked.

    ``run`` is called with ``quick`` and any argument ``extend`` adds, by its destination name.
    """
    arguments_parser = parser(description)
    if extend is not None:
        extend(arguments_parser)
    arguments = vars(arguments_parser.parse_args(argv))
    json_path = arguments.pop("json")
    print(f"machine: {summary()}", flush=True)
    try:
        result = run(**arguments)
    except CannotRun as error:
        print(f"cannot run: {error}", file=sys.stderr, flush=True)
        return 2
    print(result.text(), flush=True)
    if json_path is not None:
        json_path.parent.mkdir(parents=True, exist_ok=True)
        json_path.write_text(json.dumps(json_safe(result.to_dict()), indent=1) + "\n")
    return 0
