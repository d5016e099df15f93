"""Post-training quantisation of an OpenVINO model to 8-bit integers, with NNCF.

Why: on a CPU with VNNI (most x86 laptops and robot computers since 2019) an int8 convolution
does four multiply-adds where float32 does one, and the detector is most of the pipeline's cost
(issue 16: twice the speed of bfloat16 on this machine's two cores, measured by
``bench/bench_inference.py``). Quantisation needs no retraining: NNCF runs the float model over a
few hundred calibration images, records each activation's range, and inserts quantise /
dequantise pairs around the layers it can run in integers (then "fast bias correction" moves each
layer's mean output back to float's).

What must stay in floating point is named by ``ignored_patterns`` (regular expressions over node
names): a detector's post-processing decodes box offsets against anchor boxes and compares scores
in non-maximum suppression, where integer rounding would move boxes and, measured, even turn class
ids into wrong ones. NNCF is needed only to quantise (``sailor export-models`` or a node's first
start); the quantised model then runs on OpenVINO alone.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from typing import Any

import numpy as np

from merlin2_sailor.errors import DependencyError

NNCF_HINT = "pip install nncf==3.4.0 (scripts/setup.sh does), or set inference_precision to auto"


def nncf_version() -> str:
    """The installed NNCF's version (part of a quantised model's fingerprint), or a DependencyError."""
    return _nncf().__version__


def quantise(model: Any, calibration: Sequence[np.ndarray], ignored_patterns: Sequence[str]) -> Any:
    """``model`` (an ``openvino.Model``) with int8 weights and activations, calibrated on ``calibration``
    (each one input batch, as the model takes it); nodes matching ``ignored_patterns`` stay float."""
    if not calibration:
        raise ValueError("quantisation needs at least one calibration input")
    nncf = _nncf()
    logging.getLogger("nncf").setLevel(logging.WARNING)  # its per-step INFO lines; its progress bars stay
    return nncf.quantize(
        model, nncf.Dataset(list(calibration)), subset_size=len(calibration),
        ignored_scope=nncf.IgnoredScope(patterns=list(ignored_patterns), validate=False),
    )


def _nncf():  # -> the nncf module (imported lazily: only quantising needs it)
    try:
        import nncf
    except ImportError as error:
        raise DependencyError(f"Quantising a model to int8 needs NNCF: {NNCF_HINT}.") from error
    return nncf
