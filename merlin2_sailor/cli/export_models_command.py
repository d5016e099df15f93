"""``sailor export-models``: export every network the nodes run for the OpenVINO inference runtime.

Nodes export a missing model themselves on first use when torch is installed; this command does it
ahead of time, and is how a runtime-only deployment (OpenVINO, no torch) gets its models: run it on
a machine with torch, copy the folder, and point ``SAILOR_MODEL_CACHE`` at it. Exports are named by
a hash of their source, so running it again exports nothing that is already there.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from pathlib import Path

from merlin2_sailor.inference.model_cache import CACHE_VARIABLE, ExportedModel, cache_folder


def add_parser(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "export-models", help="export the detector, the crop backbone and the matching network for OpenVINO",
        description="Convert the SSD-MobileNet graph (in float and quantised to int8), the EfficientNet-Lite0 "
                    "crop backbone and the matching network's weights (the shipped ones, or --weights) into "
                    f"OpenVINO models in the model cache (${CACHE_VARIABLE}, else "
                    "~/.cache/merlin2_sailor/models). Needs torch for the backbone and the network, NNCF for "
                    "the int8 detector; what is already exported is skipped.",
    )
    parser.add_argument("--output", type=Path, default=None, metavar="FOLDER",
                        help=f"the model cache to write (default: {cache_folder()})")
    parser.add_argument("--weights", default="", metavar="FILE",
                        help="matching network weights to export (default: the shipped ones)")
    parser.add_argument("--backbone", default="", metavar="NAME",
                        help="crop backbone to export (default: the one the weights were trained with)")
    parser.add_argument("--backbone-weights", default="", metavar="FILE",
                        help="the backbone's weights file, for a backbone without bundled weights")
    parser.set_defaults(run=run)


def run(arguments: argparse.Namespace) -> int:
    from merlin2_sailor.anchoring.openvino_matcher import ensure_matching_network
    from merlin2_sailor.models import DEFAULT_BACKBONE, default_weights_path
    from merlin2_sailor.perception.backbone_registry import BACKBONES
    from merlin2_sailor.perception.openvino_backbone import ensure_backbone
    from merlin2_sailor.perception.ssd_mobilenet import (
        SsdMobileNetConfig,
        ensure_openvino_detector,
        ensure_quantised_detector,
        locate_model_directory,
    )

    folder = arguments.output.expanduser() if arguments.output else cache_folder()
    weights = Path(arguments.weights).expanduser() if arguments.weights else default_weights_path()
    backbone = arguments.backbone or DEFAULT_BACKBONE
    print(f"model cache: {folder}")
    steps: list[tuple[str, Callable[[], ExportedModel]]] = [
        ("SSD-MobileNet-v2 COCO detector",
         lambda: ensure_openvino_detector(locate_model_directory(), SsdMobileNetConfig().input_size, folder)),
        ("SSD-MobileNet-v2 COCO detector in int8 (NNCF)",
         lambda: ensure_quantised_detector(locate_model_directory(), SsdMobileNetConfig().input_size, folder)),
        (f"{backbone} crop backbone",
         lambda: ensure_backbone(backbone, lambda: BACKBONES.create(backbone, arguments.backbone_weights),
                                 arguments.backbone_weights, folder)),
        (f"matching network {weights.name}", lambda: ensure_matching_network(weights, backbone, folder)),
    ]
    for label, export in steps:
        started = time.monotonic()
        print(f"  {label} ... ", end="", flush=True)
        exported = export()
        print(f"{exported.folder.name} ({time.monotonic() - started:.1f} s)", flush=True)
    return 0
