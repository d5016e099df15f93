"""Entry point of the ``sailor`` command-line tool.

Each subcommand lives in its own module exposing ``add_parser(subparsers)`` and ``run(args)``;
adding one is adding a module to SUBCOMMANDS. Errors the user can fix (SailorError) are printed
as one clear line instead of a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from merlin2_sailor import __version__
from merlin2_sailor.errors import SailorError

SUBCOMMANDS = (
    "merlin2_sailor.cli.demo_command",
    "merlin2_sailor.cli.launch_command",
    "merlin2_sailor.cli.knowledge_command",
    "merlin2_sailor.cli.anchors_command",
    "merlin2_sailor.cli.train_command",
    "merlin2_sailor.cli.evaluate_command",
    "merlin2_sailor.cli.replay",
    "merlin2_sailor.cli.bench",
    "merlin2_sailor.cli.export_models_command",
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="sailor",
        description="SAILOR symbolic anchoring for ROS 2 Jazzy (merlin2_sailor).",
    )
    parser.add_argument("--version", action="version", version=f"merlin2_sailor {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for module_name in SUBCOMMANDS:
        importlib.import_module(module_name).add_parser(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    arguments = build_parser().parse_args(argv)
    try:
        return int(arguments.run(arguments) or 0)
    except SailorError as error:
        print(f"sailor {arguments.command}: error: {error}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
