"""Calibration images for quantising the detector: real photos that every installation has.

Quantisation (:mod:`merlin2_sailor.inference.quantisation`) needs inputs whose activations span
what the camera will produce. The photos bundled with scikit-image (a dependency of every node:
an astronaut, a cat, a coffee cup, a rocket, coins, a street camera man, ...) are real photographs,
need no download and are not the darknet photos the parity tests detect on, so a test measures
the quantised detector on images it was not calibrated with. Each image is a random crop (a third
of the photo to all of it), maybe mirrored, with its brightness and contrast changed, resized as
the detector resizes a frame: views at many scales and exposures, as a moving robot's camera gives.
Grey photos are repeated over the three channels (an indoor camera in dim light is nearly grey).
The set is a function of its arguments only: the same seed gives the same images, so an
exported model is reproducible, and its fingerprint names :data:`CALIBRATION_VERSION`.
"""

from __future__ import annotations

import numpy as np

#: Bump when the images change for the same arguments: every quantised detector is then made anew.
CALIBRATION_VERSION = 1
#: Images NNCF calibrates on (its own default is 300; 150 gave the same detections here in half the time).
CALIBRATION_IMAGES = 150
#: scikit-image's bundled photos (``skimage.data``), colour and grey; none needs a download.
PHOTOS = ("astronaut", "chelsea", "coffee", "rocket", "immunohistochemistry", "hubble_deep_field",
          "camera", "coins", "clock", "moon", "brick", "grass", "gravel", "page")


def calibration_images(size: int, count: int = CALIBRATION_IMAGES, seed: int = 0) -> list[np.ndarray]:
    """``count`` (1, size, size, 3) uint8 RGB batches (see the module docstring)."""
    import cv2
    import skimage.data

    photos = [_as_rgb(getattr(skimage.data, name)()) for name in PHOTOS]
    generator = np.random.default_rng(seed)
    images = []
    for index in range(count):
        photo = photos[index % len(photos)]
        height, width = photo.shape[:2]
        share = generator.uniform(1.0 / 3.0, 1.0)
        crop_height, crop_width = max(int(height * share), 8), max(int(width * share), 8)
        top = int(generator.integers(0, height - crop_height + 1))
        left = int(generator.integers(0, width - crop_width + 1))
        crop = photo[top:top + crop_height, left:left + crop_width]
        if generator.random() < 0.5:
            crop = crop[:, ::-1]
        gain, bias = generator.uniform(0.6, 1.3), generator.uniform(-30.0, 30.0)
        crop = np.clip(crop.astype(np.float32) * gain + bias, 0.0, 255.0).astype(np.uint8)
        resized = cv2.resize(np.ascontiguousarray(crop), (size, size), interpolation=cv2.INTER_LINEAR)
        images.append(resized[np.newaxis])
    return images


def _as_rgb(photo: np.ndarray) -> np.ndarray:
    if photo.ndim == 2:
        return np.repeat(photo[:, :, np.newaxis], 3, axis=2)
    return np.ascontiguousarray(photo[:, :, :3])
