"""``--record FOLDER``: any launch also records its topics to a rosbag2 bag.

The bag_recorder node joins the launch with config/bag_recorder.yaml and the folder; its end
does not stop the launch (a recorder is an observer). The folder is checked before anything
starts, so a bag that would be written over is one clear error instead of a launch without one.
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.launcher.spec import ExitPolicy, LaunchSpec, NodeSpec

RECORDER_EXECUTABLE = "bag_recorder"
STORAGES = ("mcap", "sqlite3")


def with_recorder(spec: LaunchSpec, folder: str | Path, storage: str = "mcap") -> LaunchSpec:
    """``spec`` with a bag_recorder node writing ``folder`` (which must not exist yet)."""
    from merlin2_sailor.resources import config_file

    path = Path(folder).expanduser().resolve()
    if path.exists():
        raise ConfigurationError(f"--record {folder}: {path} exists already; a bag is never written over")
    if storage not in STORAGES:
        raise ConfigurationError(f"--record-storage {storage}: choose one of {', '.join(STORAGES)}")
    recorder = NodeSpec(executable=RECORDER_EXECUTABLE,
                        parameters=(config_file("bag_recorder.yaml"), {"path": str(path), "storage": storage}),
                        on_exit=ExitPolicy.IGNORE)
    return dataclasses.replace(spec, nodes=(*spec.nodes, recorder))


def add_record_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--record", default="", metavar="FOLDER",
                        help="also record the camera, percepts, anchors and knowledge changes to a rosbag2 bag "
                             "in FOLDER (new); replay it with `sailor replay bag FOLDER`, open it in Foxglove")
    parser.add_argument("--record-storage", default="mcap", choices=STORAGES,
                        help="the bag's storage (default mcap)")
