"""Default weights that ship with the package: the matching network trained on the generated source.

``matching_network_efficientnet_lite0.pt``: a :class:`~merlin2_sailor.anchoring.matching_network.MatchingNetwork`
for EfficientNet-Lite0 crop features (1280-d), written by ``save_network`` with its metadata
header (backbone, feature encoding version, time scale). Beside it,
``matching_network_efficientnet_lite0.json`` records how it was made: the generated source's
configuration and fingerprint, the pair data set's hash, the training configuration, the
per-epoch history and the wall time.

Both are made by one command, from a checkout: ``scripts/make_default_weights.sh`` (a
``sailor train`` with fixed seeds on the generated source, then ``sailor evaluate`` on held-out
test scenes). Measured with ``sailor evaluate --seed 0`` on the 30 held-out ``test`` scenes (threshold 0.5;
look-alike = same class, nearer than 1 m)::

                            pairs  positive  accuracy precision    recall        F1
    network                 13547      1163    0.9959    0.9751    0.9768    0.9759
    rules                   13547      1163    0.9867    0.8790    0.9802    0.9268
    network look-alike       2030      1145    0.9813    0.9751    0.9921    0.9835
    rules look-alike         2030      1145    0.9202    0.8790    0.9956    0.9337

    anchoring  percepts  objects  anchors  ID sw.    IDF1    MOTA
    network        1534      371      397      29  0.9726  0.9811
    rules          1534      371      393      31  0.9720  0.9798

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
