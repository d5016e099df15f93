"""Which inference runtime a node runs its networks with, on which device, with how many threads.

A robot shares its cores between many nodes, so the thread count is a setting of each node rather
than whatever a library guesses (OpenVINO and torch both take every core by default).
"""

from __future__ import annotations

from dataclasses import dataclass

from merlin2_sailor.errors import ConfigurationError

#: ``openvino``: exported models run by OpenVINO (the default: fastest here, no torch at run time);
#: ``native``: each network in the framework it was written in (torch for the crop backbones and the
#: matching network, OpenCV DNN for the SSD detector), the baseline the benchmarks compare against.
RUNTIMES = ("openvino", "native")

#: ``f32``: float32 throughout, as torch computes (the default: what the matching network's weights
#: were validated with); ``auto``: the device's fastest precision, bfloat16 on CPUs with AVX-512
#: BF16 or AMX, about twice float32's speed. Measured on real photos (``bench_inference.py``,
#: the parity tests): crop features then differ from float32's by up to 5 % of the median distance
#: between two objects' crops, match scores by up to 0.05, detection scores by up to 0.04 (and two
#: classes nearly tied on one box may swap ranks).
PRECISIONS = ("f32", "auto")

#: ``int8``: the detector only: its convolutions in 8-bit integers, quantised after training by
#: NNCF (:mod:`merlin2_sailor.inference.quantisation`) with calibration photos that are not the test
#: photos; the post-processing (box decoding, non-maximum suppression) stays in floating point.
#: About twice ``auto``'s speed on CPUs with VNNI, and the detector is most of the pipeline's cost.
#: Not offered for the crop backbone and the matching network, whose outputs decide identities
#: and were validated in float32.
QUANTISED_PRECISION = "int8"
DETECTOR_PRECISIONS = (*PRECISIONS, QUANTISED_PRECISION)

#: OpenVINO device names this project selects by: the CPU, an integrated or discrete GPU, or
#: OpenVINO's automatic choice. A device the machine lacks falls back to the CPU with one log line.
DEVICES = ("CPU", "GPU", "AUTO")


@dataclass(frozen=True, slots=True)
class InferenceSettings:
    """``runtime``: one of :data:`RUNTIMES`; ``device``: one of :data:`DEVICES` (OpenVINO only);
    ``threads``: threads for inference, 0 for the runtime's own choice (every core); ``precision``:
    one of :data:`DETECTOR_PRECISIONS` (OpenVINO only; torch and OpenCV DNN compute in float32;
    ``int8`` for the detector only, see :meth:`require_float`)."""

    runtime: str = "openvino"
    device: str = "CPU"
    threads: int = 0
    precision: str = "f32"

    def __post_init__(self) -> None:
        if self.runtime not in RUNTIMES:
            raise ConfigurationError(
                f"Unknown inference runtime {self.runtime!r}; choose one of {', '.join(RUNTIMES)}.")
        device = self.device.upper()
        if device not in DEVICES:
            raise ConfigurationError(f"Unknown inference device {self.device!r}; choose one of {', '.join(DEVICES)}.")
        object.__setattr__(self, "device", device)
        if self.precision not in DETECTOR_PRECISIONS:
            raise ConfigurationError(f"Unknown inference precision {self.precision!r}; choose one of "
                                     f"{', '.join(DETECTOR_PRECISIONS)} ({QUANTISED_PRECISION}: the detector only).")
        if self.threads < 0:
            raise ConfigurationError(f"inference threads must be 0 (the runtime's choice) or more, got {self.threads}.")

    def require_float(self, network: str) -> None:
        """Refuse ``int8`` for ``network``: only the detector is quantised (see :data:`QUANTISED_PRECISION`)."""
        if self.precision == QUANTISED_PRECISION:
            raise ConfigurationError(
                f"inference precision {QUANTISED_PRECISION} is for the detector only; the {network} runs in "
                f"{' or '.join(PRECISIONS)}.")

    def apply_to_torch(self) -> None:
        """Give torch this thread count (process-wide: torch has one pool), for the native runtime."""
        if self.threads:
            import torch

            torch.set_num_threads(self.threads)

    def describe(self) -> str:
        """One phrase for a node's start-up log line."""
        threads = "all cores" if self.threads == 0 else f"{self.threads} thread{'s' if self.threads > 1 else ''}"
        if self.runtime == "native":
            return f"native runtime (torch / OpenCV DNN), {threads}"
        return f"OpenVINO on {self.device}, {threads}, {self.precision} precision"
