"""Public data sets as training sources, chosen by a ``--source`` value: one table above the sources.

``--source nuscenes:DATAROOT[:VERSION]`` or ``motfront:ROOT``: what comes before the first colon
names the source, what follows it is the source's own specification, which its class reads with
``from_specification``. The table holds ``"module:class"`` strings, so this module imports no
source (nor cv2, numpy or a devkit): the ``sailor`` command line builds its help from it at once,
and the sources, which import :mod:`.external_source` (the port they share), never import the
table that names them. The generated source is not here: it is the default, built from its own
options (``--seed``, ``--no-darknet``). A new public source is a module with an ``ImageSource``
subclass and its ``from_specification``, plus one entry here.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import TYPE_CHECKING

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.plugins import PluginTable

if TYPE_CHECKING:
    from merlin2_sailor.training.external_source import ImageSource

SEPARATOR = ":"


@dataclass(frozen=True, slots=True)
class SourceEntry:
    """One public source: ``target`` (``"module:class"``) and ``form``, how ``--source`` names it."""

    target: str
    form: str


SOURCE_ENTRIES: Mapping[str, SourceEntry] = MappingProxyType({
    "nuscenes": SourceEntry(
        "merlin2_sailor.training.nuscenes_source:NuScenesSource",
        "nuscenes:DATAROOT[:VERSION] (nuScenes' JSON tables, e.g. nuscenes:/data/nuscenes:v1.0-mini)",
    ),
    "motfront": SourceEntry("merlin2_sailor.training.motfront_source:MotFrontSource", "motfront:ROOT"),
})

SOURCES = PluginTable("data source", {name: entry.target for name, entry in SOURCE_ENTRIES.items()})

#: The forms of every public source, for help texts and errors.
SOURCE_FORMS = " or ".join(entry.form for entry in SOURCE_ENTRIES.values())


def open_source(specification: str) -> ImageSource:
    """The public source a ``--source`` value names, e.g. ``motfront:/data/motfront``."""
    name, _, rest = specification.partition(SEPARATOR)
    if name not in SOURCES or not rest:
        raise ConfigurationError(f"Unknown data source {specification!r}: use generated, {SOURCE_FORMS}.")
    return SOURCES.load(name).from_specification(rest)
