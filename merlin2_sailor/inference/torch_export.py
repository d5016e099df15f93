"""Converting a torch module to an OpenVINO model file: the one place the exports call OpenVINO's
converter, so every export writes full float32 weights and hides the tracer's chatter alike.

Weights stay float32 (OpenVINO compresses them to float16 by default), because the parity tests
and the matching threshold are stated for the scores torch computes. torch is imported by the
caller, who built the module.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any


def save_torch_module(module: Any, example_input: Any, input_shapes: Sequence[tuple[int, ...]], path: Path,
                      input_names: Sequence[str] = ()) -> None:
    """Convert ``module`` (evaluation mode) with ``-1`` marking dynamic sizes in ``input_shapes``, and
    save it as ``path`` (an ``.xml`` beside its ``.bin``); ``input_names`` name the model's inputs."""
    import openvino

    with warnings.catch_warnings():
        # The converter traces the module with torch.jit, which warns that tracing is deprecated
        # and that traced shapes are constants: neither matters for these fixed graphs.
        warnings.simplefilter("ignore")
        model = openvino.convert_model(module, example_input=example_input, input=list(input_shapes))
    for port, name in zip(model.inputs, input_names, strict=False):
        port.get_tensor().set_names({name})
    openvino.save_model(model, str(path), compress_to_fp16=False)
