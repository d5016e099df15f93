"""Synthetic scenes for the anchoring tests: objects, noisy percepts of them, cameras, depth.

Appearance is synthetic on purpose: each physical object (an *identity*) gets a random unit
vector, and every percept of it that vector plus a little noise, so "same object" and "same
class, different object" are controlled exactly and no backbone runs. Two identities can share
one vector to model identical-looking objects (two white mugs). Everything is seeded.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from merlin2_sailor.anchoring.features import FeatureConfig, PairFeatures
from merlin2_sailor.anchoring.matcher import Matcher
from merlin2_sailor.anchoring.rule_matcher import RuleMatcher
from merlin2_sailor.anchoring.visibility import CameraView
from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.percept import BoundingBox2D, Percept
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.perception.colour_histogram import COLOUR_BINS, HUE_BINS

#: A small camera (160 x 120, ~77 degrees horizontal field of view) keeps depth images cheap.
TEST_INTRINSICS = CameraIntrinsics(fx=100.0, fy=100.0, cx=79.5, cy=59.5, width=160, height=120)

#: Rotation from the optical frame (z forward, x right, y down) to a world frame with z up,
#: for a camera looking along world +x.
_OPTICAL_TO_FORWARD_X = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])


@dataclass(frozen=True)
class SceneObject:
    """A physical object: who it is (``identity``), what class, where, how big."""

    identity: str
    class_name: str
    position: tuple[float, float, float]
    size: tuple[float, float, float] = (0.1, 0.1, 0.12)
    looks_like: str = ""
    """Another identity whose appearance this object shares (identical-looking objects)."""
    colour: np.ndarray | None = field(default=None, compare=False)
    """The colour histogram of the object's own pixels (see :func:`mug_colour`); percepts carry
    it with a little noise; None: percepts have no colour."""


def mug_colour(hue_bin: int, share: float = 0.15) -> np.ndarray:
    """A histogram like the demo's mugs: most pixels shared by every mug of the make (coffee,
    shadow: hue bins 0-1, dark grey), ``share`` of them in the mug's own hue bin."""
    histogram = np.zeros(COLOUR_BINS)
    histogram[[0, 1, HUE_BINS]] = np.array([0.35, 0.45, 0.2]) * (1.0 - share)
    histogram[hue_bin] += share
    return histogram / histogram.sum()


@dataclass
class PerceptMaker:
    """Makes noisy percepts of scene objects; one instance per test (it owns its random state)."""

    seed: int = 0
    dimension: int = 32
    position_noise: float = 0.01
    appearance_noise: float = 0.05
    colour_noise: float = 0.01
    _rng: np.random.Generator = field(init=False)
    _appearances: dict[str, np.ndarray] = field(init=False, default_factory=dict)

    def __post_init__(self) -> None:
        self._rng = np.random.default_rng(self.seed)

    def appearance(self, identity: str) -> np.ndarray:
        if identity not in self._appearances:
            vector = np.abs(self._rng.normal(size=self.dimension))
            self._appearances[identity] = (vector / np.linalg.norm(vector)).astype(np.float32)
        return self._appearances[identity]

    def percept(
        self,
        item: SceneObject,
        stamp: float,
        tracker_id: str = "",
        class_name: str | None = None,
        position: tuple[float, float, float] | np.ndarray | None = None,
        with_embedding: bool = True,
        crop: np.ndarray | None = None,
    ) -> Percept:
        base = np.asarray(item.position if position is None else position, dtype=np.float64)
        embedding = None
        if with_embedding:
            clean = self.appearance(item.looks_like or item.identity)
            noise = self._rng.normal(scale=self.appearance_noise / math.sqrt(self.dimension), size=self.dimension)
            embedding = (clean + noise).astype(np.float32)
        colour = None
        if item.colour is not None:
            colour = np.clip(item.colour + self._rng.normal(scale=self.colour_noise, size=COLOUR_BINS), 0.0, None)
            colour = (colour / colour.sum()).astype(np.float32)
        return Percept(
            class_name=class_name or item.class_name,
            score=0.9,
            box=BoundingBox2D(80.0, 60.0, 20.0, 20.0),
            position=base + self._rng.normal(scale=self.position_noise, size=3),
            size=np.asarray(item.size, dtype=np.float64) * (1.0 + self._rng.normal(scale=0.02, size=3)),
            stamp=stamp,
            crop=np.zeros((0, 0, 3), dtype=np.uint8) if crop is None else crop,
            tracker_id=tracker_id,
            embedding=embedding,
            colour=colour,
        )


def looking_along_x(position: tuple[float, float, float], yaw: float = 0.0) -> Pose:
    """A camera-to-world pose at ``position`` looking horizontally, ``yaw`` radians from +x."""
    cos, sin = math.cos(yaw), math.sin(yaw)
    yaw_rotation = np.array([[cos, -sin, 0.0], [sin, cos, 0.0], [0.0, 0.0, 1.0]])
    return Pose(yaw_rotation @ _OPTICAL_TO_FORWARD_X, np.asarray(position, dtype=np.float64))


def camera_view(
    position: tuple[float, float, float] = (0.0, 0.0, 1.0), yaw: float = 0.0, depth: np.ndarray | None = None
) -> CameraView:
    return CameraView(TEST_INTRINSICS, looking_along_x(position, yaw), depth)


def flat_depth(value: float) -> np.ndarray:
    """A depth image of a wall at ``value`` metres (or NaN for "no depth anywhere")."""
    return np.full((TEST_INTRINSICS.height, TEST_INTRINSICS.width), value, dtype=np.float32)


def with_occluder(
    depth: np.ndarray, view: CameraView, behind: tuple[float, float, float], distance: float
) -> np.ndarray:
    """Put a surface at ``distance`` metres over the pixels around where ``behind`` projects."""
    camera_point = view.camera_to_world.inverse().transform_points(np.asarray(behind, dtype=np.float64).reshape(1, 3))
    pixels, _ = view.intrinsics.project(camera_point)
    column, row = np.rint(pixels[0]).astype(int)
    occluded = depth.copy()
    occluded[max(row - 10, 0) : row + 11, max(column - 10, 0) : column + 11] = distance
    return occluded


#: A kitchen seen from a camera at (0, 0, 1) looking along +x: everything 2-3 m ahead.
KITCHEN = (
    SceneObject("red_cup", "cup", (2.0, 0.3, 0.8)),
    SceneObject("blue_bowl", "bowl", (2.5, -0.4, 0.8), (0.2, 0.2, 0.08)),
    SceneObject("apple", "apple", (2.2, 0.0, 0.85), (0.08, 0.08, 0.08)),
)

#: Two identical-looking mugs a metre apart on the same table.
TWIN_MUGS = (
    SceneObject("left_mug", "cup", (2.5, 0.5, 0.8)),
    SceneObject("right_mug", "cup", (2.5, -0.5, 0.8), looks_like="left_mug"),
)


class AppearanceRules(Matcher):
    """Rules times appearance: 1 for the same look, near 0 for another (unit embeddings)."""

    uses_appearance = True

    def __init__(self) -> None:
        self.rules = RuleMatcher()

    @property
    def feature_config(self) -> FeatureConfig:
        return self.rules.feature_config

    def score_pairs(self, features: PairFeatures) -> np.ndarray:
        scores = self.rules.score_pairs(features)
        known = features.appearance_known
        likeness = np.ones(len(features))
        likeness[known] = np.exp(-((features.appearance_distance[known] / 2.0) ** 2) * 4.0)
        return scores * likeness
