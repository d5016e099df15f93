"""Read one mapping of a world file with errors that name the file, the entry and the field.

A world file is edited by hand, so every mistake must come back as one ConfigurationError that
says where it is and what was expected ("house.yaml: objects[3] (red_mug): 'size' must be 3
positive numbers, got [0.1, 0.1]"), never as a KeyError from deep inside the simulator.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any

from merlin2_sailor.errors import ConfigurationError

_REQUIRED = object()


class Fields:
    """The fields of one YAML mapping at ``where``; unknown keys are refused up front."""

    def __init__(self, data: Any, where: str, known: Iterable[str]) -> None:
        if not isinstance(data, Mapping):
            raise ConfigurationError(f"{where}: expected a mapping of fields, got {type(data).__name__} {data!r}")
        self.where = where
        self._data = data
        unknown = sorted(str(key) for key in data if key not in set(known))
        if unknown:
            raise ConfigurationError(f"{where}: unknown field(s) {unknown}; known fields: {sorted(known)}")

    def has(self, key: str) -> bool:
        return key in self._data and self._data[key] is not None

    def raw(self, key: str, default: Any = _REQUIRED) -> Any:
        if not self.has(key):
            if default is _REQUIRED:
                raise ConfigurationError(f"{self.where}: the field '{key}' is required")
            return default
        return self._data[key]

    def fail(self, key: str, expected: str) -> ConfigurationError:
        return ConfigurationError(f"{self.where}: '{key}' must be {expected}, got {self._data.get(key)!r}")

    def number(self, key: str, default: Any = _REQUIRED, minimum: float | None = None,
               maximum: float | None = None) -> float:
        value = self.raw(key, default)
        if value is default and default is not _REQUIRED:
            return value
        if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
            raise self.fail(key, "a finite number")
        if (minimum is not None and value < minimum) or (maximum is not None and value > maximum):
            raise self.fail(key, f"a number in [{minimum}, {maximum}]")
        return float(value)

    def integer(self, key: str, default: Any = _REQUIRED, minimum: int | None = None) -> int:
        value = self.raw(key, default)
        if value is default and default is not _REQUIRED:
            return value
        if isinstance(value, bool) or not isinstance(value, int) or (minimum is not None and value < minimum):
            raise self.fail(key, f"an integer >= {minimum}" if minimum is not None else "an integer")
        return int(value)

    def text(self, key: str, default: Any = _REQUIRED) -> str:
        value = self.raw(key, default)
        if value is default and default is not _REQUIRED:
            return value
        if not isinstance(value, str) or not value.strip():
            raise self.fail(key, "a non-empty string")
        return value.strip()

    def vector(self, key: str, length: int | tuple[int, ...], default: Any = _REQUIRED,
               positive: bool = False) -> tuple[float, ...]:
        value = self.raw(key, default)
        if value is default and default is not _REQUIRED:
            return value
        lengths = (length,) if isinstance(length, int) else length
        numbers_ok = isinstance(value, list | tuple) and all(
            not isinstance(item, bool) and isinstance(item, int | float) and math.isfinite(item) for item in value
        )
        if not numbers_ok or len(value) not in lengths or (positive and any(item <= 0 for item in value)):
            count = " or ".join(str(n) for n in lengths)
            raise self.fail(key, f"{count} {'positive ' if positive else ''}numbers")
        return tuple(float(item) for item in value)

    def color(self, key: str, default: Any = _REQUIRED) -> tuple[int, int, int]:
        value = self.raw(key, default)
        if value is default and default is not _REQUIRED:
            return value
        if not (isinstance(value, list | tuple) and len(value) == 3
                and all(isinstance(item, int) and not isinstance(item, bool) and 0 <= item <= 255 for item in value)):
            raise self.fail(key, "an RGB colour [r, g, b] of integers 0-255")
        return (int(value[0]), int(value[1]), int(value[2]))

    def boolean(self, key: str, default: Any = _REQUIRED) -> bool:
        value = self.raw(key, default)
        if not isinstance(value, bool):
            raise self.fail(key, "true or false")
        return value

    def sequence(self, key: str, default: Any = _REQUIRED) -> list[Any]:
        value = self.raw(key, default)
        if not isinstance(value, list):
            raise self.fail(key, "a list")
        return value

    def names(self, key: str, default: Any = _REQUIRED) -> tuple[str, ...]:
        value = self.raw(key, default)
        if isinstance(value, str):
            value = [value]
        if not isinstance(value, list | tuple) or not all(isinstance(item, str) and item for item in value):
            raise self.fail(key, "a name or a list of names")
        return tuple(value)
