"""The replay sources by name, each imported only when chosen (like the detector backends)."""

from __future__ import annotations

import dataclasses
import importlib
from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor_demos.replay.source import ReplaySource

#: Source name -> "module:class"; each class has a ``config_class`` dataclass of its options.
REPLAY_SOURCES = MappingProxyType(
    {
        "motorcycle": "merlin2_sailor_demos.replay.motorcycle:MotorcycleSource",
        "sr300": "merlin2_sailor_demos.replay.sr300:Sr300CastelSource",
        "vtest": "merlin2_sailor_demos.replay.vtest:VtestSource",
        "bag": "merlin2_sailor_demos.replay.bag_source:BagSource",
    }
)


def source_class(name: str) -> type[ReplaySource]:
    if name not in REPLAY_SOURCES:
        raise ConfigurationError(f"unknown replay source '{name}'; choose one of {', '.join(REPLAY_SOURCES)}")
    module_name, class_name = REPLAY_SOURCES[name].split(":")
    return getattr(importlib.import_module(module_name), class_name)


def create_source(name: str, options: Mapping[str, Any] | None = None) -> ReplaySource:
    """Build the source called ``name`` with the configuration fields ``options``.

    Fails with a :class:`ConfigurationError` naming the source's options when given one it lacks.
    """
    source = source_class(name)
    config_class = source.config_class  # type: ignore[attr-defined]
    fields = {field.name for field in dataclasses.fields(config_class) if field.init}
    unknown = set(options or {}) - fields
    if unknown:
        raise ConfigurationError(
            f"the '{name}' source has no option {', '.join(sorted(unknown))}"
            f" (its options: {', '.join(sorted(fields)) or 'none'})"
        )
    return source(config_class(**dict(options or {})))  # type: ignore[call-arg]
