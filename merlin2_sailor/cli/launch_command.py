"""``sailor launch``: start a graph of nodes from a YAML launch file (ros2 launch is not on PyPI)."""

from __future__ import annotations

import argparse
import os
import signal
from types import FrameType

from merlin2_sailor.launcher import Supervisor, load_launch_file
from merlin2_sailor.launcher.recording import add_record_arguments, with_recorder
from merlin2_sailor.resources import config_file, find_launch_file

# Fast DDS reads its profile from this variable; ours enlarges the shared-memory segment so that
# camera images between local processes do not fall back to lossy fragmented UDP.
FAST_DDS_PROFILE_VARIABLE = "FASTRTPS_DEFAULT_PROFILES_FILE"


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "launch",
        help="start a graph of nodes from a YAML launch file",
        description=(
            "Start every node of a YAML launch file as its own process, prefix each output line "
            "with the node's name, and stop all of them cleanly on Ctrl-C, when one of them "
            "exits, or after --duration seconds. Exits 0 when every node ended cleanly."
        ),
    )
    parser.add_argument(
        "launch_file", help="a launch file path, or the name of a shipped one (e.g. 'camera')"
    )
    parser.add_argument(
        "--duration", type=float, default=None, metavar="SECONDS",
        help="stop the launch after this many seconds (default: run until Ctrl-C)",
    )
    add_grace_period_argument(parser)
    add_record_arguments(parser)
    parser.set_defaults(run=run)


def add_grace_period_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--grace-period", type=float, default=10.0, metavar="SECONDS",
        help="how long nodes get to shut down, at Ctrl-C or the end, before they are terminated (default 10)",
    )


def run(arguments: argparse.Namespace) -> int:
    spec = load_launch_file(find_launch_file(arguments.launch_file))
    if arguments.record:
        spec = with_recorder(spec, arguments.record, arguments.record_storage)
    if FAST_DDS_PROFILE_VARIABLE not in os.environ and FAST_DDS_PROFILE_VARIABLE not in spec.environment:
        spec.environment[FAST_DDS_PROFILE_VARIABLE] = str(config_file("fastdds.xml"))
    supervisor = Supervisor(spec, grace_period=arguments.grace_period)

    def on_signal(signal_number: int, _frame: FrameType | None) -> None:
        supervisor.request_stop(f"received {signal.Signals(signal_number).name}")

    previous = {number: signal.signal(number, on_signal) for number in (signal.SIGINT, signal.SIGTERM)}
    try:
        result = supervisor.run(duration=arguments.duration)
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)
    print(result.summary(), flush=True)
    return 0 if result.succeeded else 1
