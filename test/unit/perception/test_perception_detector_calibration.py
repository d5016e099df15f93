"""The detector's calibration photos and the quantiser's guards (no model is quantised here)."""

from __future__ import annotations

import sys

import numpy as np
import pytest

from merlin2_sailor.errors import DependencyError
from merlin2_sailor.perception.detector_calibration import calibration_images

pytest.importorskip("cv2", reason="pip install opencv-python-headless")
pytest.importorskip("skimage", reason="pip install scikit-image")


def test_calibration_images_are_reproducible_batches_of_the_detectors_input() -> None:
    first, again = calibration_images(96, count=20), calibration_images(96, count=20)
    assert len(first) == 20
    assert all(image.shape == (1, 96, 96, 3) and image.dtype == np.uint8 for image in first)
    assert all(np.array_equal(a, b) for a, b in zip(first, again, strict=True))  # an export is reproducible
    other = calibration_images(96, count=20, seed=1)
    assert not all(np.array_equal(a, b) for a, b in zip(first, other, strict=True))


def test_calibration_images_span_exposures_and_scenes() -> None:
    images = np.concatenate(calibration_images(64, count=40))
    means = images.reshape(len(images), -1).mean(axis=1)
    assert means.max() - means.min() > 60  # dark and bright views, as a moving camera gives
    assert len({image.tobytes() for image in images}) == len(images)  # no two alike
    colour = np.abs(images[..., 0].astype(int) - images[..., 2]).mean(axis=(1, 2))
    assert (colour > 5).sum() >= 10 and (colour < 1).sum() >= 10  # colour photos and grey ones


def test_quantising_without_nncf_says_how_to_get_it(monkeypatch) -> None:
    from merlin2_sailor.inference import quantisation

    monkeypatch.setitem(sys.modules, "nncf", None)  # not installed: importing it fails
    with pytest.raises(DependencyError, match=r"pip install nncf==3\.4\.0.*inference_precision to auto"):
        quantisation.quantise(object(), [np.zeros((1, 8, 8, 3), dtype=np.uint8)], ())
    with pytest.raises(ValueError, match="at least one calibration input"):
        quantisation.quantise(object(), [], ())
