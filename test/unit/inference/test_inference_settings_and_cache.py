"""The inference runtime's settings, its device fallback and the model cache (no model is run here)."""

from __future__ import annotations

import threading
from pathlib import Path

import pytest

pytest.importorskip("openvino", reason="pip install openvino==2026.4.1")

from merlin2_sailor.errors import ConfigurationError  # noqa: E402
from merlin2_sailor.inference.model_cache import (  # noqa: E402
    MODEL_FILE,
    cache_folder,
    find_exported,
    fingerprint,
    store_exported,
)
from merlin2_sailor.inference.openvino_runtime import choose_device  # noqa: E402
from merlin2_sailor.inference.settings import InferenceSettings  # noqa: E402


def test_settings_refuse_what_no_runtime_has_and_say_the_choices() -> None:
    assert InferenceSettings(device="gpu").device == "GPU"  # people type it either way
    with pytest.raises(ConfigurationError, match="choose one of openvino, native"):
        InferenceSettings(runtime="tensorrt")
    with pytest.raises(ConfigurationError, match="choose one of CPU, GPU, AUTO"):
        InferenceSettings(device="NPU0")
    with pytest.raises(ConfigurationError, match="threads"):
        InferenceSettings(threads=-1)
    assert "2 threads" in InferenceSettings(threads=2).describe()
    assert "all cores" in InferenceSettings().describe()


def test_a_device_the_machine_lacks_falls_back_to_the_cpu_in_one_line() -> None:
    heard: list[str] = []
    assert choose_device("GPU", ["CPU"], heard.append) == "CPU"
    assert len(heard) == 1 and "GPU is not available" in heard[0] and "CPU" in heard[0]
    assert choose_device("GPU", ["CPU", "GPU.0"], heard.append) == "GPU"  # numbered GPUs count
    assert choose_device("AUTO", ["CPU"], heard.append) == "AUTO"
    assert len(heard) == 1


def test_the_cache_folder_follows_the_environment(monkeypatch, tmp_path: Path) -> None:
    monkeypatch.setenv("SAILOR_MODEL_CACHE", str(tmp_path / "models"))
    assert cache_folder() == tmp_path / "models"
    monkeypatch.delenv("SAILOR_MODEL_CACHE")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache_folder() == tmp_path / "xdg" / "merlin2_sailor" / "models"


def test_a_fingerprint_changes_with_the_source_file_and_its_description(tmp_path: Path) -> None:
    weights = tmp_path / "weights.pt"
    weights.write_bytes(b"first")
    first = fingerprint("backbone", weights)
    assert fingerprint("backbone", weights) == first
    assert fingerprint("other backbone", weights) != first
    weights.write_bytes(b"second")  # retrained: a new export, never the stale one
    assert fingerprint("backbone", weights) != first


def _write_model(target: Path) -> dict[str, object]:
    (target / MODEL_FILE).write_text("<net/>")
    return {"size": 3}


def test_an_export_lands_whole_once_even_when_two_writers_race(tmp_path: Path) -> None:
    barrier = threading.Barrier(2)

    def write(target: Path) -> dict[str, object]:
        barrier.wait(timeout=10)  # both writers are mid-export at the same time
        return _write_model(target)

    results = []
    threads = [threading.Thread(target=lambda: results.append(store_exported("net", "abc", write, tmp_path)))
               for _ in range(2)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=20)
    assert len(results) == 2 and results[0].folder == results[1].folder == tmp_path / "net-abc"
    assert results[0].metadata == {"size": 3, "name": "net", "fingerprint": "abc"}
    assert sorted(path.name for path in tmp_path.iterdir()) == ["net-abc"]  # no staging folder left


def test_a_failed_export_leaves_nothing_that_looks_finished(tmp_path: Path) -> None:
    def failing(target: Path) -> dict[str, object]:
        (target / MODEL_FILE).write_text("<half")
        raise RuntimeError("converter crashed")

    with pytest.raises(RuntimeError, match="converter crashed"):
        store_exported("net", "abc", failing, tmp_path)
    assert find_exported("net", "abc", tmp_path) is None
    assert list(tmp_path.iterdir()) == []


def test_a_damaged_export_is_one_clear_error_not_a_traceback(tmp_path: Path) -> None:
    from merlin2_sailor.errors import DependencyError
    from merlin2_sailor.inference.openvino_runtime import CompiledNetwork

    model = tmp_path / "net-abc" / MODEL_FILE
    model.parent.mkdir()
    model.write_text("<net name='half written'")  # a disk filled up mid-export, say
    with pytest.raises(DependencyError, match="could not load .*sailor export-models"):
        CompiledNetwork(model, InferenceSettings(threads=1))


def test_int8_is_the_detectors_alone_and_says_so_elsewhere() -> None:
    assert InferenceSettings(precision="int8").precision == "int8"
    with pytest.raises(ConfigurationError, match="int8: the detector only"):
        InferenceSettings(precision="int4")
    InferenceSettings(precision="auto").require_float("crop backbone")
    with pytest.raises(ConfigurationError, match="for the detector only; the crop backbone runs in f32 or auto"):
        InferenceSettings(precision="int8").require_float("crop backbone")


def test_the_anchoring_node_refuses_int8_for_its_networks() -> None:
    from merlin2_sailor.anchoring.settings import load_anchoring_settings

    with pytest.raises(ConfigurationError, match="inference_precision"):
        load_anchoring_settings(overrides={"inference_precision": "int8"})
