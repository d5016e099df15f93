"""Odometry drifts with the distance driven and is reset by the localiser on arrival."""

from __future__ import annotations

import math

import numpy as np

from merlin2_sailor_demos.world.geometry import Pose2D
from merlin2_sailor_demos.world.odometry import Odometry, OdometryNoise
from merlin2_sailor_demos.world.world import NavigationState, World

from .worlds import room_world


def _straight_drive(seed: int, metres: float, noise: OdometryNoise) -> tuple[Pose2D, Pose2D]:
    truth = Pose2D(0.0, 0.0, 0.0)
    odometry = Odometry(noise, np.random.default_rng(seed), truth)
    for _ in range(int(metres / 0.01)):
        after = truth.compose(0.01, 0.0, 0.0)
        odometry.update(truth, after, 0.02)
        truth = after
    return truth, odometry.estimate


def test_drift_grows_with_distance_but_stays_bounded() -> None:
    noise = OdometryNoise()
    errors = {metres: [] for metres in (1.0, 5.0)}
    for seed in range(20):
        for metres in errors:
            truth, estimate = _straight_drive(seed, metres, noise)
            errors[metres].append(math.hypot(truth.x - estimate.x, truth.y - estimate.y))
    assert np.mean(errors[1.0]) < np.mean(errors[5.0])
    assert 0.005 < np.mean(errors[5.0]) < 0.25  # centimetres to decimetres over 5 m, like wheel odometry
    assert max(errors[5.0]) < 0.5


def test_without_noise_the_estimate_is_the_truth() -> None:
    zero = OdometryNoise(*([0.0] * len(OdometryNoise.FIELDS)))
    truth, estimate = _straight_drive(0, 3.0, zero)
    assert math.hypot(truth.x - estimate.x, truth.y - estimate.y) < 1e-9


def test_the_world_corrects_the_estimate_on_arrival() -> None:
    world = World(room_world(size=(8.0, 4.0), start=(1.0, 2.0, 0.0)), seed=3)
    world.navigate_to(7.0, 1.0, math.pi / 2)
    drifted = 0.0
    while world.navigation.state is NavigationState.ACTIVE:
        world.step(0.1)
        drifted = max(drifted, math.hypot(world.true_pose.x - world.estimated_pose.x,
                                          world.true_pose.y - world.estimated_pose.y))
        assert world.time < 60.0
    assert drifted > 0.002  # the estimate did wander while driving
    truth, estimate = world.true_pose, world.estimated_pose
    localiser = world.description.robot.odometry
    assert math.hypot(truth.x - estimate.x, truth.y - estimate.y) < 4 * localiser.localisation_position * 1.5
    assert truth.distance_to(7.0, 1.0) < 0.3  # the controller drove on the estimate, so the truth is near


def test_a_periodic_localiser_keeps_the_estimate_close_all_along_a_drive(house_description) -> None:
    """Without it the estimate drifts over a whole drive; with a fix each second it stays near the truth."""
    import dataclasses

    def worst_error(period: float) -> float:
        robot = house_description.robot
        odometry = dataclasses.replace(robot.odometry, localisation_period=period)
        world = World(dataclasses.replace(house_description, robot=dataclasses.replace(robot, odometry=odometry)),
                      seed=1)
        worst = 0.0
        for waypoint in ("bedroom", "kitchen"):
            pose = next(w.pose for w in house_description.house.waypoints if w.name == waypoint)
            goal = world.navigate_to(pose.x, pose.y)
            while goal.state is NavigationState.ACTIVE:
                world.step(1 / 15)
                estimate, truth = world.estimated_pose, world.true_pose
                worst = max(worst, math.hypot(estimate.x - truth.x, estimate.y - truth.y))
        return worst

    assert worst_error(1.0) < 0.06 < worst_error(0.0)


def test_the_localisation_period_is_read_from_the_world_file() -> None:
    assert OdometryNoise.from_mapping({"localisation_period": 2.5}, "robot.odometry").localisation_period == 2.5
    assert OdometryNoise.from_mapping({}, "robot.odometry").localisation_period == 0.0
