"""Where exported models live: one folder per model, named by what it was exported from.

An exported model is a function of its source (a weights file, a TensorFlow graph), of the export
code and of the runtime's format, so its folder is named ``<name>-<fingerprint>`` with a hash of all
three: a retrained weights file or a new exporter gets a new folder instead of a stale model, and
the old one is never read again. Folders are written under a temporary name and renamed into place
(atomic on one file system), so two nodes that export the same model at once both end with a
whole one, and a crash mid-export leaves nothing that looks finished.

The cache is ``$SAILOR_MODEL_CACHE`` when set (a runtime-only deployment points it at the folder
``sailor export-models`` wrote on a machine with torch), else ``$XDG_CACHE_HOME/merlin2_sailor/models``
(``~/.cache/merlin2_sailor/models``).
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import tempfile
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

from merlin2_sailor.errors import DependencyError

#: Bump when the export code changes what it writes: every cached model is then exported anew.
EXPORT_FORMAT = 1
MODEL_FILE = "model.xml"
METADATA_FILE = "metadata.json"
CACHE_VARIABLE = "SAILOR_MODEL_CACHE"


def cache_folder() -> Path:
    """The folder exported models are read from and written to (see the module docstring)."""
    configured = os.environ.get(CACHE_VARIABLE, "")
    if configured:
        return Path(configured).expanduser()
    base = os.environ.get("XDG_CACHE_HOME", "") or str(Path.home() / ".cache")
    return Path(base) / "merlin2_sailor" / "models"


@lru_cache(maxsize=32)
def _file_digest(path: str, size: int, modified_ns: int) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def fingerprint(*sources: Path | str) -> str:
    """A short hash of the export format, the runtime's version and each source (file contents or text)."""
    import openvino

    digest = hashlib.sha256(f"format {EXPORT_FORMAT}; openvino {openvino.__version__}".encode())
    for source in sources:
        if isinstance(source, Path):
            status = source.stat()
            digest.update(_file_digest(str(source.resolve()), status.st_size, status.st_mtime_ns).encode())
        else:
            digest.update(source.encode())
    return digest.hexdigest()[:16]


@dataclass(frozen=True, slots=True)
class ExportedModel:
    """An exported model's folder: ``model.xml`` (+ ``model.bin``) and the metadata it was written with."""

    folder: Path
    metadata: Mapping[str, Any]

    @property
    def model_path(self) -> Path:
        return self.folder / MODEL_FILE


def find_exported(name: str, model_fingerprint: str, folder: Path | None = None) -> ExportedModel | None:
    """The exported model ``name`` with this fingerprint, or None when it has not been exported."""
    model_folder = (folder or cache_folder()) / f"{name}-{model_fingerprint}"
    if not (model_folder / MODEL_FILE).is_file() or not (model_folder / METADATA_FILE).is_file():
        return None
    return ExportedModel(model_folder, json.loads((model_folder / METADATA_FILE).read_text()))


def store_exported(
    name: str, model_fingerprint: str, write: Callable[[Path], Mapping[str, Any]], folder: Path | None = None
) -> ExportedModel:
    """Run ``write(folder)`` (it writes ``model.xml``/``.bin`` there and returns the metadata) into a
    temporary folder, then rename it into place; if another process got there first, keep theirs."""
    root = folder or cache_folder()
    root.mkdir(parents=True, exist_ok=True)
    final = root / f"{name}-{model_fingerprint}"
    staging = Path(tempfile.mkdtemp(prefix=f".{name}-", dir=root))
    try:
        metadata = dict(write(staging))
        metadata.setdefault("name", name)
        metadata["fingerprint"] = model_fingerprint
        (staging / METADATA_FILE).write_text(json.dumps(metadata, indent=2, sort_keys=True) + "\n")
        try:
            staging.rename(final)
        except OSError:  # another process renamed its copy first: theirs is as good as ours
            if find_exported(name, model_fingerprint, root) is None:
                raise
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    exported = find_exported(name, model_fingerprint, root)
    assert exported is not None
    return exported


def ensure_exported(name: str, model_fingerprint: str, write: Callable[[Path], Mapping[str, Any]], what: str,
                    needs_torch: bool, folder: Path | None = None,
                    report: Callable[[str], None] | None = None) -> ExportedModel:
    """The exported model, exporting it first when missing (said in one line through ``report``);
    ``what`` names it in messages; ``needs_torch``: the export needs torch, so without torch a
    missing export is an error saying how to get one, not an ImportError from deep inside."""
    exported = find_exported(name, model_fingerprint, folder)
    if exported is not None:
        return exported
    if needs_torch:
        try:
            import torch  # noqa: F401  (only to tell a missing export from a missing torch)
        except ImportError as error:
            raise DependencyError(
                f"No exported {what} in the model cache ({folder or cache_folder()}), and torch (needed to export "
                f"it) is not installed. Run `sailor export-models` on a machine with torch and point "
                f"{CACHE_VARIABLE} at its output.") from error
    started = time.monotonic()
    exported = store_exported(name, model_fingerprint, write, folder)
    if report is not None:
        report(f"exported {what} for OpenVINO in {time.monotonic() - started:.1f} s "
               f"(once; cached in {exported.folder})")
    return exported
