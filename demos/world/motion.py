"""How the simulated robot drives a path: turn toward the next point, then drive straight to it.

The follower is a controller: it reads the pose the robot believes it has (odometry) and commands
velocities; the world applies them to the true pose (:func:`integrate`), so odometry drift shows
up as a true arrival pose slightly off the goal, as on a real robot.

A differential-drive base with speed and acceleration limits on both axes. Velocities change by
at most ``acceleration * dt`` per step, and the speed toward a point, or toward a heading,
follows the braking curve ``sqrt(2 * acceleration * remaining)``, so the robot stops on each point
without overshooting. At the last point it turns to the goal's heading, if one was given.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from enum import Enum
from typing import Any

from merlin2_sailor_demos.world.geometry import Pose2D, wrap_angle
from merlin2_sailor_demos.world.yaml_fields import Fields


@dataclass(frozen=True, slots=True)
class MotionLimits:
    """Speed (m/s, rad/s) and acceleration (m/s^2, rad/s^2) limits, and arrival tolerances (m, rad)."""

    max_linear_speed: float = 0.5
    max_linear_acceleration: float = 0.5
    max_angular_speed: float = 1.0
    max_angular_acceleration: float = 2.0
    position_tolerance: float = 0.03
    heading_tolerance: float = 0.03
    #: While driving, a heading error above this (rad) stops the robot to turn in place again.
    realign_threshold: float = 0.4
    #: Gain (1/s) of the heading correction while driving.
    heading_gain: float = 2.0

    @classmethod
    def from_fields(cls, fields: Fields) -> MotionLimits:
        return cls(
            fields.number("max_linear_speed", 0.5, minimum=0.01, maximum=5.0),
            fields.number("max_linear_acceleration", 0.5, minimum=0.01, maximum=20.0),
            fields.number("max_angular_speed", 1.0, minimum=0.01, maximum=10.0),
            fields.number("max_angular_acceleration", 2.0, minimum=0.01, maximum=50.0),
            fields.number("position_tolerance", 0.03, minimum=0.001, maximum=1.0),
            fields.number("heading_tolerance", 0.03, minimum=0.001, maximum=1.0),
        )

    FIELDS = ("max_linear_speed", "max_linear_acceleration", "max_angular_speed", "max_angular_acceleration",
              "position_tolerance", "heading_tolerance")


#: Speeds (m/s, rad/s) below which the robot counts as stopped, so the final stop is a small step.
STOPPED_LINEAR_SPEED = 0.01
STOPPED_ANGULAR_SPEED = 0.02


class Phase(Enum):
    TURN = "turn"
    DRIVE = "drive"
    FINAL_TURN = "final_turn"
    STOPPING = "stopping"
    DONE = "done"


@dataclass(frozen=True, slots=True)
class Velocity:
    linear: float = 0.0
    angular: float = 0.0


class PathFollower:
    """Follows one path; ``step`` advances the true pose by ``dt`` seconds."""

    def __init__(self, limits: MotionLimits, path: Sequence[tuple[float, float]], final_yaw: float | None = None,
                 velocity: Velocity | None = None) -> None:
        self.limits = limits
        self.path = [(float(x), float(y)) for x, y in path]
        self.final_yaw = final_yaw
        self.velocity = velocity or Velocity()
        self._index = 0
        self.phase = Phase.TURN if self.path else (Phase.FINAL_TURN if final_yaw is not None else Phase.DONE)

    @property
    def done(self) -> bool:
        return self.phase is Phase.DONE

    def remaining_distance(self, pose: Pose2D) -> float:
        if not self.path or self._index >= len(self.path):
            return 0.0
        distance = pose.distance_to(*self.path[self._index])
        for start, end in zip(self.path[self._index:], self.path[self._index + 1:], strict=False):
            distance += math.dist(start, end)
        return distance

    def command(self, pose: Pose2D, dt: float) -> Velocity:
        """The velocity to hold for the next ``dt`` seconds (keep it small, ~0.02 s), from the pose the
        robot believes it has; the change from the last command respects the acceleration limits."""
        if self.phase is Phase.DONE or dt <= 0.0:
            return self.velocity
        linear_target, angular_target = self._targets(pose, dt)
        if self.phase is Phase.DONE:
            self.velocity = Velocity()
            return self.velocity
        limits = self.limits
        linear = _approach(self.velocity.linear, linear_target, limits.max_linear_acceleration * dt)
        angular = _approach(self.velocity.angular, angular_target, limits.max_angular_acceleration * dt)
        self.velocity = Velocity(linear, angular)
        return self.velocity

    def stop(self) -> None:
        """Abandon the path and brake to a standstill within the acceleration limits."""
        self.phase = Phase.STOPPING

    def _targets(self, pose: Pose2D, dt: float) -> tuple[float, float]:
        limits = self.limits
        if self.phase in (Phase.TURN, Phase.DRIVE):
            target = self.path[self._index]
            distance = pose.distance_to(*target)
            if distance < limits.position_tolerance and abs(self.velocity.linear) < STOPPED_LINEAR_SPEED:
                self._index += 1
                if self._index < len(self.path):
                    self.phase = Phase.TURN
                else:
                    self.phase = Phase.FINAL_TURN if self.final_yaw is not None else Phase.DONE
                return self._targets(pose, dt) if self.phase is not Phase.DONE else (0.0, 0.0)
            error = wrap_angle(math.atan2(target[1] - pose.y, target[0] - pose.x) - pose.yaw)
            if self.phase is Phase.TURN:
                if distance < limits.position_tolerance:
                    return 0.0, 0.0  # close enough; let the linear speed settle before moving on
                if abs(error) < limits.heading_tolerance and abs(self.velocity.angular) < 0.1:
                    self.phase = Phase.DRIVE
                else:
                    return 0.0, self._turn_speed(error, dt)
            if abs(error) > limits.realign_threshold:
                self.phase = Phase.TURN
                return 0.0, self._turn_speed(error, dt)
            braking = math.sqrt(2.0 * limits.max_linear_acceleration * distance)
            linear = min(limits.max_linear_speed, braking, distance / dt) * max(math.cos(error), 0.0)
            angular = max(-limits.max_angular_speed, min(limits.max_angular_speed, limits.heading_gain * error))
            return linear, angular
        if self.phase is Phase.FINAL_TURN:
            error = wrap_angle(float(self.final_yaw) - pose.yaw)
            if abs(error) < limits.heading_tolerance and abs(self.velocity.angular) < STOPPED_ANGULAR_SPEED:
                self.phase = Phase.DONE
                return 0.0, 0.0
            return 0.0, self._turn_speed(error, dt)
        if self.phase is Phase.STOPPING and (abs(self.velocity.linear) < STOPPED_LINEAR_SPEED
                                             and abs(self.velocity.angular) < STOPPED_ANGULAR_SPEED):
            self.phase = Phase.DONE
        return 0.0, 0.0

    def _turn_speed(self, error: float, dt: float) -> float:
        limits = self.limits
        braking = math.sqrt(2.0 * limits.max_angular_acceleration * abs(error))
        speed = min(limits.max_angular_speed, braking, abs(error) / dt)
        return math.copysign(speed, error)


def _approach(current: float, target: float, largest_change: float) -> float:
    return current + max(-largest_change, min(largest_change, target - current))


def integrate(pose: Pose2D, velocity: Velocity, dt: float) -> Pose2D:
    """Exact unicycle motion over dt at constant velocities (an arc, or a line when angular is 0)."""
    linear, angular = velocity.linear, velocity.angular
    turn = angular * dt
    if abs(turn) < 1e-9:
        return pose.compose(linear * dt, 0.0, 0.0)
    radius = linear / angular
    return pose.compose(radius * math.sin(turn), radius * (1.0 - math.cos(turn)), turn)


def limits_from_mapping(data: Any, where: str) -> MotionLimits:
    return MotionLimits.from_fields(Fields(data, where, MotionLimits.FIELDS))
