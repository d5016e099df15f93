"""Compiling an exported model for a device, with the thread count and precision this project needs.

Two choices are made here once for every network: the precision (``auto`` lets OpenVINO take the
device's fastest, bfloat16 on CPUs with AVX-512 BF16 or AMX, about twice float32's speed; ``f32``
keeps float32 throughout, for exact parity with torch), and a latency hint (one frame at a time,
as a camera delivers them, rather than throughput over many parallel requests). A device the machine lacks
(``GPU`` on a laptop without one) is reported in one line and replaced by the CPU.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from merlin2_sailor.errors import DependencyError
from merlin2_sailor.inference.model_cache import cache_folder
from merlin2_sailor.inference.settings import InferenceSettings

OPENVINO_HINT = "Install the OpenVINO runtime (`pip install openvino==2026.4.1`; scripts/setup.sh does)."

_logger = logging.getLogger(__name__)

#: Changes a read model before it is compiled (for example, pre-processing folded into its graph);
#: typed loosely, ``openvino.Model -> openvino.Model``, as openvino is imported lazily.
ModelPreparation = Callable[[Any], Any]
_core_lock = threading.Lock()
_core = None


def openvino_core():  # -> openvino.Core (typed loosely: openvino is imported lazily)
    """The process's one OpenVINO Core (it caches device plug-ins, so one is enough)."""
    global _core
    with _core_lock:
        if _core is None:
            try:
                import openvino
            except ImportError as error:
                raise DependencyError(f"The openvino inference runtime is not installed. {OPENVINO_HINT}") from error
            _core = openvino.Core()
            # Compiled blobs are cached beside the exported models: a node's second start, or a
            # second detector in one process, skips the compilation (seconds on two cores).
            _core.set_property({"CACHE_DIR": str(cache_folder() / "compiled")})
        return _core


def choose_device(requested: str, available: Sequence[str], report: Callable[[str], None]) -> str:
    """``requested`` if the machine has it (``GPU`` matches ``GPU.0``), else the CPU, said once."""
    if requested in ("CPU", "AUTO") or any(device.split(".")[0] == requested for device in available):
        return requested
    report(f"inference device {requested} is not available on this machine (it has {', '.join(available) or 'none'}); "
           "running on the CPU")
    return "CPU"


def _configuration(settings: InferenceSettings, device: str) -> dict[str, object]:
    """OpenVINO properties for ``device``: latency first, the precision asked for, the thread count
    (a CPU property: a GPU runs on its own threads)."""
    config: dict[str, object] = {"PERFORMANCE_HINT": "LATENCY"}
    if settings.precision == "f32":
        config["INFERENCE_PRECISION_HINT"] = "f32"
    if settings.threads and device == "CPU":
        config["INFERENCE_NUM_THREADS"] = settings.threads
    return config


class CompiledNetwork:
    """A model compiled for one device: call it with NumPy arrays, get its outputs as arrays.

    One inference request, guarded by a lock: nodes call from one worker thread, and the lock makes
    a second caller wait rather than corrupt the request's buffers.
    """

    def __init__(self, model_path: Path, settings: InferenceSettings,
                 report: Callable[[str], None] | None = None, prepare: ModelPreparation | None = None) -> None:
        core = openvino_core()
        report = report or _logger.warning
        self.device = choose_device(settings.device, core.available_devices, report)

        def model():  # -> openvino.Model or its path; OpenVINO's CACHE_DIR keeps the compiled blob of either
            return prepare(core.read_model(str(model_path))) if prepare else str(model_path)

        try:
            self._compiled = core.compile_model(model(), self.device, _configuration(settings, self.device))
        except Exception as error:  # OpenVINO raises RuntimeError subclasses of its own
            if self.device == "CPU":
                raise DependencyError(
                    f"OpenVINO could not load {model_path}: {' '.join(str(error).split())[:300]}. Delete that "
                    "folder and run `sailor export-models`, or set inference_runtime to native.") from error
            report(f"inference device {self.device} failed to load {model_path.parent.name} "
                   f"({' '.join(str(error).split())[:200]}); running on the CPU")
            self.device = "CPU"
            self._compiled = core.compile_model(model(), "CPU", _configuration(settings, "CPU"))
        self._request = self._compiled.create_infer_request()
        self._lock = threading.Lock()
        self._output_names = tuple(frozenset(port.get_names()) for port in self._compiled.outputs)

    def output_index(self, name: str) -> int:
        """Where the output called ``name`` is in what a call returns."""
        for index, names in enumerate(self._output_names):
            if name in names:
                return index
        raise KeyError(f"the model has no output {name!r}")

    @property
    def threads(self) -> int:
        """Threads the runtime runs this model with (what a node reports)."""
        try:
            return int(self._compiled.get_property("INFERENCE_NUM_THREADS"))
        except Exception:  # a device without the property (GPU) runs on its own threads
            return 0

    def __call__(self, *inputs: np.ndarray) -> list[np.ndarray]:
        with self._lock:
            results = self._request.infer([np.ascontiguousarray(array) for array in inputs])
            return [np.array(results[port]) for port in self._compiled.outputs]
