"""The package's public API: every export resolves; importing a percept stays light; no ROS."""

from __future__ import annotations

import subprocess
import sys

import merlin2_sailor.anchoring as anchoring


def test_every_public_name_resolves():
    for name in anchoring.__all__:
        assert getattr(anchoring, name) is not None, name
    assert set(anchoring.__all__) <= set(dir(anchoring))


def loaded_after(statement: str, modules: tuple[str, ...]) -> list[str]:
    """Which of ``modules`` a fresh interpreter has loaded after running ``statement``."""
    code = f"import sys; {statement}; print(','.join(m for m in {modules!r} if m in sys.modules))"
    output = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    return [name for name in output.strip().split(",") if name]


def test_the_perceptual_layer_pays_only_for_the_percept():
    assert loaded_after("import merlin2_sailor.contract.percept", ("scipy", "torch", "rclpy")) == []


def test_the_core_needs_neither_torch_nor_ros():
    assert loaded_after("from merlin2_sailor.anchoring import Anchoring", ("torch", "rclpy")) == []
