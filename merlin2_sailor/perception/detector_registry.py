"""Detector backends chosen by name: one table above the backends, and one function that builds one.

The table holds ``"module:class"`` strings, so choosing one backend imports only that one: the
OpenCV DNN model or Ultralytics (and torch behind it) cost nothing to a deployment that does not
use them. It sits above the backends, which import the :class:`~.detector.Detector` port below,
so the table and its plug-ins never import each other. A new backend is a module with a
``Detector`` subclass (and its ``config_class``) plus one line here.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from typing import Any

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.perception.detector import Detector
from merlin2_sailor.plugins import PluginTable

#: Backend name -> "module:class".
DETECTOR_BACKENDS = PluginTable(
    "detector backend",
    {
        "ssd_mobilenet": "merlin2_sailor.perception.ssd_mobilenet:SsdMobileNetDetector",
        "ultralytics": "merlin2_sailor.perception.ultralytics_backend:UltralyticsDetector",
    },
    hint="Run scripts/setup.sh, which installs every backend's libraries.",
)


def create_detector(name: str, options: Mapping[str, Any] | None = None,
                    report: Callable[[str], None] | None = None) -> Detector:
    """Build the detector backend called ``name`` with its configuration fields ``options``;
    ``report`` hears what the caller should log once (a model converted, a device replaced).

    Raises:
        ConfigurationError: an unknown backend, or an option it does not have or refuses.
        DependencyError: the backend's libraries or model files are missing.
    """
    backend: type[Detector] = DETECTOR_BACKENDS.load(name)
    config_fields = {field.name for field in dataclasses.fields(backend.config_class)}
    unknown = set(options or {}) - config_fields
    if unknown:
        raise ConfigurationError(
            f"Detector {name!r} has no option(s) {', '.join(sorted(unknown))}; "
            f"its options are {', '.join(sorted(config_fields))}."
        )
    return backend(backend.config_class(**dict(options or {})), report)
