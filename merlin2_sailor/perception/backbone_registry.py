"""Crop backbones chosen by name: one table above the backbones, and one function that builds one.

The backbone modules import torch themselves, so this table (``"module:class"`` strings) and a
deployment without torch stay light; a missing torch is one clear error. The table sits above the
backbones, which import the :class:`~.backbone.Backbone` port below, so the two never import each
other. A new backbone is a module with a ``Backbone`` subclass plus one line here.
"""

from __future__ import annotations

from collections.abc import Callable

from merlin2_sailor.inference.settings import InferenceSettings
from merlin2_sailor.perception.backbone import Backbone
from merlin2_sailor.plugins import PluginTable

#: Backbone name -> "module:class".
BACKBONES = PluginTable(
    "backbone",
    {
        "efficientnet_lite0": "merlin2_sailor.perception.efficientnet_lite0:EfficientNetLite0Backbone",
        "resnet18": "merlin2_sailor.perception.resnet18:ResNet18Backbone",
    },
    hint="The backbones need torch (`pip install torch==2.13.0`, a CPU build; scripts/setup.sh installs it).",
)


def create_backbone(name: str, weights_path: str = "", inference: InferenceSettings | None = None,
                    report: Callable[[str], None] | None = None) -> Backbone:
    """Build the backbone called ``name`` for the configured inference runtime (OpenVINO by default,
    exported once from the torch backbone; ``native`` runs torch itself); ``weights_path`` is needed
    by those without bundled weights; ``report`` hears what a node should log (an export, a device
    fallback)."""
    if name not in BACKBONES:
        BACKBONES.load(name)  # raises the table's error, which lists the known names
    inference = inference or InferenceSettings()
    if inference.runtime == "openvino":
        from merlin2_sailor.perception.openvino_backbone import OpenVinoBackbone

        return OpenVinoBackbone.for_backbone(
            name, weights_path, inference, lambda: BACKBONES.create(name, weights_path), report)
    inference.apply_to_torch()
    return BACKBONES.create(name, weights_path)
