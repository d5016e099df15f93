"""What the depth camera makes of the true depth: limited range, noise growing with distance, dropouts.

Structured-light and stereo RGB-D cameras measure nothing closer than a few decimetres or beyond
a few metres, and their error grows roughly with the square of the distance (Khoshelham and
Elberink, 2012: about 1.5 mm at 0.5 m, 4 cm at 5 m for the Kinect). Measured depth is the true
depth plus Gaussian noise of standard deviation ``noise_base + noise_quadratic * z**2``; pixels
outside [minimum_range, maximum_range], and a random ``dropout`` fraction, are invalid (NaN).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor_demos.world.yaml_fields import Fields


@dataclass(frozen=True, slots=True)
class DepthSensorConfig:
    minimum_range: float = 0.3
    maximum_range: float = 6.0
    noise_base: float = 0.001
    noise_quadratic: float = 0.0015
    dropout: float = 0.002

    def __post_init__(self) -> None:
        if not 0.0 <= self.minimum_range < self.maximum_range:
            raise ConfigurationError(
                f"depth sensor needs 0 <= minimum_range < maximum_range, got {self.minimum_range}, {self.maximum_range}"
            )

    def noise_sigma(self, depth: np.ndarray | float) -> np.ndarray | float:
        return self.noise_base + self.noise_quadratic * np.square(depth)

    def measure(self, true_depth: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """float32 metres, NaN where the sensor returns nothing."""
        true_depth = np.asarray(true_depth, dtype=np.float32)
        noise = rng.standard_normal(true_depth.shape, dtype=np.float32)
        measured = true_depth + noise * self.noise_sigma(true_depth).astype(np.float32)
        invalid = ~((true_depth >= self.minimum_range) & (true_depth <= self.maximum_range))
        if self.dropout > 0.0:
            invalid |= rng.random(true_depth.shape, dtype=np.float32) < self.dropout
        measured[invalid] = np.nan
        return measured

    @classmethod
    def from_mapping(cls, data: Any, where: str = "depth_sensor") -> DepthSensorConfig:
        fields = Fields(data, where, ("minimum_range", "maximum_range", "noise_base", "noise_quadratic", "dropout"))
        return cls(
            fields.number("minimum_range", 0.3, minimum=0.0), fields.number("maximum_range", 6.0, minimum=0.1),
            fields.number("noise_base", 0.001, minimum=0.0), fields.number("noise_quadratic", 0.0015, minimum=0.0),
            fields.number("dropout", 0.002, minimum=0.0, maximum=1.0),
        )
