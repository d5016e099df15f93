"""What counts as a place watched: cells the camera could see around a percept, less unknown objects."""

from __future__ import annotations

import numpy as np

from merlin2_sailor.anchoring.visibility import VisibilityConfig
from merlin2_sailor.anchoring.watched_places import WatchConfig, WatchedPlaces

from .anchoring_scenes import PerceptMaker, SceneObject, camera_view, flat_depth, with_occluder

BOWL = SceneObject("bowl", "bowl", (2.5, 0.0, 0.8), (0.2, 0.2, 0.08))
BESIDE = np.array((2.5, 0.45, 0.8))
FAR_AWAY = np.array((2.5, 2.0, 0.8))


def places() -> WatchedPlaces:
    return WatchedPlaces(WatchConfig(), VisibilityConfig())


def test_the_cells_around_a_percept_in_view_are_watched_once_a_frame():
    watched, maker = places(), PerceptMaker(seed=1)
    for frame in range(4):
        watched.watch([maker.percept(BOWL, frame * 0.1)], [False], camera_view(depth=flat_depth(4.0)))
    assert watched.watched_without(BESIDE, "cup") == 4
    assert watched.watched_without(FAR_AWAY, "cup") == 0


def test_cells_hidden_behind_nearer_depth_are_not_watched():
    watched, maker, view = places(), PerceptMaker(seed=1), camera_view()
    depth = with_occluder(flat_depth(4.0), view, tuple(BESIDE), 1.0)
    watched.watch([maker.percept(BOWL, 0.0)], [False], camera_view(depth=depth))
    assert watched.watched_without(BESIDE, "cup") == 0
    assert watched.watched_without(np.array(BOWL.position), "cup") == 1


def test_frames_with_an_unknown_object_of_a_class_do_not_count_for_that_class():
    watched, maker = places(), PerceptMaker(seed=1)
    cup = SceneObject("cup", "cup", tuple(BESIDE))
    for frame in range(5):
        percepts = [maker.percept(BOWL, frame * 0.1), maker.percept(cup, frame * 0.1)]
        watched.watch(percepts, [False, frame < 2], camera_view())
    assert watched.watched_without(BESIDE, "cup") == 3
    assert watched.watched_without(BESIDE, "bowl") == 5


def test_nothing_is_watched_without_a_camera_or_with_the_evidence_off():
    maker = PerceptMaker(seed=1)
    without_camera, turned_off = places(), WatchedPlaces(WatchConfig(frames_to_arrive=0), VisibilityConfig())
    without_camera.watch([maker.percept(BOWL, 0.0)], [False], None)
    turned_off.watch([maker.percept(BOWL, 0.0)], [False], camera_view())
    assert len(without_camera) == len(turned_off) == 0
