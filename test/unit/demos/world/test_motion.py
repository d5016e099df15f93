"""The robot turns toward each point, then drives, within its speed and acceleration limits."""

from __future__ import annotations

import math

import pytest

from merlin2_sailor_demos.world.geometry import Pose2D, wrap_angle
from merlin2_sailor_demos.world.motion import MotionLimits, PathFollower, integrate

DT = 0.02


def _drive(follower: PathFollower, pose: Pose2D, seconds: float = 60.0) -> tuple[Pose2D, list]:
    history = []
    for _ in range(int(seconds / DT)):
        if follower.done:
            break
        velocity = follower.command(pose, DT)
        pose = integrate(pose, velocity, DT)
        history.append((pose, velocity))
    return pose, history


def test_arrives_at_the_last_point_facing_the_goal_heading() -> None:
    limits = MotionLimits()
    follower = PathFollower(limits, [(2.0, 0.0), (2.0, 3.0)], final_yaw=math.pi)
    pose, history = _drive(follower, Pose2D(0.0, 0.0, 0.0))
    assert follower.done
    assert pose.distance_to(2.0, 3.0) <= limits.position_tolerance
    assert abs(wrap_angle(pose.yaw - math.pi)) <= limits.heading_tolerance
    # 5 m at 0.5 m/s, plus accelerating, braking and two turns: well under a minute.
    assert 10.0 < len(history) * DT < 25.0


def test_speeds_and_accelerations_stay_within_the_limits() -> None:
    limits = MotionLimits()
    follower = PathFollower(limits, [(3.0, 1.0), (0.0, 2.0)], final_yaw=0.0)
    _, history = _drive(follower, Pose2D(0.0, 0.0, 2.0))
    velocities = [(0.0, 0.0)] + [(v.linear, v.angular) for _, v in history]
    for (linear, angular), (next_linear, next_angular) in zip(velocities, velocities[1:], strict=False):
        assert abs(next_linear) <= limits.max_linear_speed + 1e-9
        assert abs(next_angular) <= limits.max_angular_speed + 1e-9
        assert abs(next_linear - linear) <= limits.max_linear_acceleration * DT + 1e-9
        assert abs(next_angular - angular) <= limits.max_angular_acceleration * DT + 1e-9
    assert velocities[-1] == (0.0, 0.0)


def test_it_turns_in_place_before_driving() -> None:
    follower = PathFollower(MotionLimits(), [(0.0, 2.0)])  # 90 degrees to the left
    start = Pose2D(0.0, 0.0, 0.0)
    _, history = _drive(follower, start)
    for pose, velocity in history:
        if pose.distance_to(0.0, 2.0) < 0.1:
            continue  # the bearing to a point this close says nothing
        heading_error = abs(wrap_angle(math.atan2(2.0 - pose.y, -pose.x) - pose.yaw))
        if heading_error > 0.5:
            assert velocity.linear == pytest.approx(0.0, abs=0.05)


def test_a_stopped_goal_brakes_smoothly() -> None:
    limits = MotionLimits()
    follower = PathFollower(limits, [(5.0, 0.0)])
    pose, _ = _drive(follower, Pose2D(0.0, 0.0, 0.0), seconds=3.0)
    moving = follower.velocity.linear
    assert moving > 0.4
    follower.stop()
    _, history = _drive(follower, pose)
    assert follower.done
    assert len(history) * DT == pytest.approx(moving / limits.max_linear_acceleration, abs=0.1)
