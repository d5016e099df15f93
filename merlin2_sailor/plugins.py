"""Plug-ins chosen by name: one small table per kind (stores, detectors, backbones, matchers, sources).

Each kind keeps a table of ``name -> "module:attribute"`` strings one level above its plug-ins, so
that choosing one plug-in imports only that one (a deployment without torch, pymongo or KANT pays
nothing for them), the table never imports its plug-ins (no import cycle between a registry and
what it registers), and every kind fails the same way: an unknown name lists the known ones, and a
plug-in whose import fails says what to install.
"""

from __future__ import annotations

import dataclasses
import importlib
from collections.abc import Iterator, Mapping
from types import MappingProxyType
from typing import Any

from merlin2_sailor.errors import ConfigurationError, DependencyError


@dataclasses.dataclass(frozen=True)
class PluginTable:
    """The plug-ins of one kind, by name, each imported only when it is loaded.

    ``kind`` names the kind in messages ("store", "detector backend"); ``entries`` maps each
    name to ``"module:attribute"``; ``hint`` is appended to the error when a plug-in's import fails
    (what to install), and ``hints`` overrides it for single names whose needs differ.
    """

    kind: str
    entries: Mapping[str, str]
    hint: str = ""
    hints: Mapping[str, str] = dataclasses.field(default_factory=dict)

    def __post_init__(self) -> None:
        for name, target in self.entries.items():
            module_name, _, attribute = target.partition(":")
            if not module_name or not attribute:
                raise ValueError(f"The {self.kind} {name!r} must be given as 'module:attribute', got {target!r}.")
        unknown_hints = set(self.hints) - set(self.entries)
        if unknown_hints:
            raise ValueError(f"Hints for unknown {self.kind} name(s): {', '.join(sorted(unknown_hints))}.")
        # Frozen copies: a table is configuration, shared by everyone who imports it.
        object.__setattr__(self, "entries", MappingProxyType(dict(self.entries)))
        object.__setattr__(self, "hints", MappingProxyType(dict(self.hints)))

    @property
    def names(self) -> tuple[str, ...]:
        """The known names, sorted, as they are listed in error messages."""
        return tuple(sorted(self.entries))

    def __contains__(self, name: object) -> bool:
        return name in self.entries

    def __iter__(self) -> Iterator[str]:
        return iter(self.names)

    def check(self, name: str) -> None:
        """Raise :class:`ConfigurationError` listing the known names unless ``name`` is one of them."""
        if name not in self.entries:
            raise ConfigurationError(f"Unknown {self.kind} {name!r}; choose one of {', '.join(self.names)}.")

    def load(self, name: str) -> Any:
        """Import the plug-in called ``name`` and return its attribute (usually a class).

        Raises :class:`ConfigurationError` for an unknown name and :class:`DependencyError`, with
        the hint, when its module (or something it needs) cannot be imported.
        """
        self.check(name)
        module_name, _, attribute = self.entries[name].partition(":")
        try:
            module = importlib.import_module(module_name)
        except ImportError as error:
            hint = self.hints.get(name, self.hint)
            raise DependencyError(
                f"The {self.kind} {name!r} cannot be loaded: {error}." + (f" {hint}" if hint else "")
            ) from error
        try:
            return getattr(module, attribute)
        except AttributeError as error:
            # A wrong table entry is this package's bug, not the user's: say exactly which one.
            raise AttributeError(
                f"The {self.kind} table names {self.entries[name]!r}, but {module_name} has no {attribute!r}."
            ) from error

    def extended(self, entries: Mapping[str, str], hints: Mapping[str, str] | None = None) -> PluginTable:
        """This table plus more plug-ins, for a layer above that adds its own (the ROS layer's stores).

        The table below stays as it is, so the core never names a plug-in of a layer above it.
        """
        clashes = set(entries) & set(self.entries)
        if clashes:
            raise ValueError(f"The {self.kind} name(s) {', '.join(sorted(clashes))} are taken already.")
        return PluginTable(self.kind, {**self.entries, **entries}, self.hint, {**self.hints, **(hints or {})})

    def create(self, name: str, *args: Any, **kwargs: Any) -> Any:
        """Load the plug-in called ``name`` and call it with the given arguments."""
        return self.load(name)(*args, **kwargs)
