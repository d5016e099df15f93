"""Where the robot believes it is: wheel odometry that drifts, reset by a localiser at waypoints.

Every motion step's true displacement (forward, sideways, turn) is measured with the errors of
real wheel odometry (Thrun, Burgard and Fox, Probabilistic Robotics, ch. 5.4): a systematic wheel
scale error and heading drift per metre, drawn once per run, plus random errors whose variance
grows with the distance driven and the angle turned (so they do not depend on the step size).
The estimate integrates those measurements and drifts away from the truth.

On arrival at a navigation goal the estimate is reset to the true pose plus a small residual
error, as a localiser (AMCL against the map) would converge once the robot stands still; this is
the only way truth leaks into the estimate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from merlin2_sailor_demos.world.geometry import Pose2D, wrap_angle
from merlin2_sailor_demos.world.yaml_fields import Fields


@dataclass(frozen=True, slots=True)
class OdometryNoise:
    """Standard deviations of the odometry and localiser errors.

    ``translation_noise`` m per sqrt(m) driven; ``rotation_noise`` rad per sqrt(rad) turned;
    ``heading_noise`` rad per sqrt(m) driven; ``scale_error`` (fraction) and ``heading_drift``
    (rad per m) are systematic, drawn once; ``localisation_position`` (m) and
    ``localisation_heading`` (rad) are the residual error after a localiser correction;
    ``localisation_period`` (s) is how often the localiser corrects while the robot moves, as AMCL
    does against a map (0: only on arrival at a goal, so drift builds up over a whole drive).
    """

    translation_noise: float = 0.005
    rotation_noise: float = 0.01
    heading_noise: float = 0.003
    scale_error: float = 0.005
    heading_drift: float = 0.003
    localisation_position: float = 0.01
    localisation_heading: float = 0.005
    localisation_period: float = 0.0

    FIELDS = ("translation_noise", "rotation_noise", "heading_noise", "scale_error", "heading_drift",
              "localisation_position", "localisation_heading", "localisation_period")

    @classmethod
    def from_mapping(cls, data: Any, where: str) -> OdometryNoise:
        fields = Fields(data, where, cls.FIELDS)
        defaults = cls()
        values = {name: fields.number(name, getattr(defaults, name), minimum=0.0, maximum=1.0)
                  for name in cls.FIELDS if name != "localisation_period"}
        period = fields.number("localisation_period", defaults.localisation_period, minimum=0.0, maximum=3600.0)
        return cls(**values, localisation_period=period)


class Odometry:
    """The pose estimate; call ``update`` after every true motion step and ``correct`` on arrival."""

    def __init__(self, noise: OdometryNoise, rng: np.random.Generator, start: Pose2D) -> None:
        self.noise = noise
        self._rng = rng
        self._scale = 1.0 + rng.normal(0.0, noise.scale_error)
        self._drift = rng.normal(0.0, noise.heading_drift)
        self.estimate = start
        self.linear_velocity = 0.0
        self.angular_velocity = 0.0

    def update(self, before: Pose2D, after: Pose2D, dt: float) -> Pose2D:
        """Integrate the measured displacement between two true poses; return the new estimate."""
        forward, left, turn = after.relative_to(before)
        distance = math.hypot(forward, left)
        rng, noise = self._rng, self.noise
        measured_forward = forward * self._scale + rng.normal(0.0, noise.translation_noise * math.sqrt(distance))
        measured_left = left * self._scale
        measured_turn = (turn + self._drift * distance
                         + rng.normal(0.0, noise.rotation_noise * math.sqrt(abs(turn)))
                         + rng.normal(0.0, noise.heading_noise * math.sqrt(distance)))
        self.estimate = self.estimate.compose(measured_forward, measured_left, measured_turn)
        if dt > 0.0:
            self.linear_velocity, self.angular_velocity = measured_forward / dt, measured_turn / dt
        return self.estimate

    def stop(self) -> None:
        self.linear_velocity = self.angular_velocity = 0.0

    def correct(self, truth: Pose2D) -> Pose2D:
        """The localiser's fix: the true pose plus the localiser's small residual error."""
        rng, noise = self._rng, self.noise
        self.estimate = Pose2D(
            truth.x + rng.normal(0.0, noise.localisation_position),
            truth.y + rng.normal(0.0, noise.localisation_position),
            wrap_angle(truth.yaw + rng.normal(0.0, noise.localisation_heading)),
        )
        return self.estimate
