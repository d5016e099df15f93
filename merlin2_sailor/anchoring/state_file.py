"""The anchoring node's state on disk: anchors, symbol counters and the objects it synced.

Anchors must survive a restart of the anchoring node, and a symbol once handed out must never
name a different object afterwards. Two files in one folder, each replaced atomically (written
aside, then renamed), so a crash leaves either the old or the new version, never half of one:

* ``symbols.json``: the last index of each class, written at once whenever an anchor is acquired
  (small, so cheap on the hot path);
* ``anchors.json``: the anchors' snapshot and the knowledge-base objects the sync owns, written
  periodically off the hot path.
"""

from __future__ import annotations

import json
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from merlin2_sailor.errors import ConfigurationError

STATE_FORMAT = 1


@dataclass
class SavedState:
    snapshot: dict[str, Any] | None = None
    owned_objects: frozenset[str] = frozenset()
    symbol_indices: dict[str, int] = field(default_factory=dict)


class AnchoringStateFile:
    def __init__(self, folder: str | os.PathLike[str]) -> None:
        self.folder = Path(folder).expanduser()
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
        except OSError as error:
            raise ConfigurationError(f"cannot create the anchoring state folder {self.folder}: {error}") from error

    def load(self) -> SavedState:
        """What the last run left; an empty state on a first run. A damaged file is an error."""
        anchors = self._read("anchors.json")
        symbols = self._read("symbols.json")
        return SavedState(
            snapshot=anchors.get("snapshot") if anchors else None,
            owned_objects=frozenset(anchors.get("owned_objects", [])) if anchors else frozenset(),
            symbol_indices={str(k): int(v) for k, v in (symbols or {}).get("indices", {}).items()},
        )

    def save_symbols(self, indices: dict[str, int]) -> None:
        self._write("symbols.json", {"format": STATE_FORMAT, "indices": indices})

    def save_anchors(self, snapshot: dict[str, Any], owned_objects: frozenset[str]) -> None:
        self._write("anchors.json", {"format": STATE_FORMAT, "snapshot": snapshot,
                                     "owned_objects": sorted(owned_objects)})

    def _read(self, name: str) -> dict[str, Any] | None:
        path = self.folder / name
        if not path.exists():
            return None
        try:
            document = json.loads(path.read_text())
        except (OSError, json.JSONDecodeError) as error:
            raise ConfigurationError(
                f"{path} is damaged ({error}); move it away to start with no anchors") from error
        if not isinstance(document, dict) or document.get("format") != STATE_FORMAT:
            raise ConfigurationError(f"{path} is not an anchoring state file of format {STATE_FORMAT}")
        return document

    def _write(self, name: str, document: dict[str, Any]) -> None:
        handle, temporary = tempfile.mkstemp(dir=self.folder, prefix=f".{name}.")
        try:
            with os.fdopen(handle, "w") as stream:
                json.dump(document, stream)
            os.replace(temporary, self.folder / name)
        except BaseException:
            Path(temporary).unlink(missing_ok=True)
            raise
