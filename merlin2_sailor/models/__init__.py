"""Default weights that ship with the package: the matching network trained on the house source.

``matching_network_efficientnet_lite0.pt``: a :class:`~merlin2_sailor.anchoring.matching_network.MatchingNetwork`
for EfficientNet-Lite0 crop features (1280-d) followed by the crop's colour and layout
descriptor (186 values, see :mod:`merlin2_sailor.perception.crop_descriptor`), written by ``save_network`` with
its metadata header (backbone, feature sizes, feature encoding version, time scale). Beside it,
``matching_network_efficientnet_lite0.json`` records how it was made: the house source's
configuration and fingerprint, the pair data set's hash, the training configuration, the
per-epoch history and the wall time.

Both are made by one command, from a checkout: ``scripts/make_default_weights.sh`` (a
``sailor train --source houses`` with fixed seeds: tours of procedurally generated houses, none
of them the demo's, rendered by the demo's renderer; then ``sailor evaluate`` on held-out test
houses and on tours of the demo's house). The figures are in the README ("Training the matching
function") and in the JSON record.

They are data, not code: regenerate them when the feature encoding, the backbone
or the generator changes (``load_network`` refuses weights whose header does not fit).
"""

from __future__ import annotations

from pathlib import Path

from merlin2_sailor.errors import DependencyError

#: The backbone the shipped weights expect, and their file names.
DEFAULT_BACKBONE = "efficientnet_lite0"
DEFAULT_WEIGHTS_FILE = "matching_network_efficientnet_lite0.pt"
DEFAULT_PROVENANCE_FILE = "matching_network_efficientnet_lite0.json"


def models_folder() -> Path:
    return Path(__file__).resolve().parent


def default_weights_path() -> Path:
    """The shipped weights file; a clear error when the installation lacks it."""
    path = models_folder() / DEFAULT_WEIGHTS_FILE
    if not path.is_file():
        raise DependencyError(
            f"The default matching network weights {path} are missing from this installation; "
            "run scripts/make_default_weights.sh in a checkout, or pass a weights file."
        )
    return path
