"""Frame-to-frame RGB-D visual odometry: where the camera moved between two frames.

Recorded RGB-D sequences often come without camera poses, and anchors live in a fixed world
frame, so a hand-held camera's motion has to be estimated. ORB corners of the previous image
that have a registered depth become 3D points in the previous camera's frame; matched to the
corners of the current image, a RANSAC perspective-n-point solve gives the current camera's pose
relative to the previous one. Chained from the first frame, that is the camera's trajectory
(with the slow drift of any odometry). When too few matches agree, the camera is assumed not to
have moved and the step is reported as lost.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from merlin2_sailor.contract.camera import CameraIntrinsics
from merlin2_sailor.contract.pose import Pose


@dataclass(frozen=True, slots=True)
class OdometryConfig:
    """``features``: ORB corners per image; ``reprojection_error`` (px): RANSAC's inlier bound;
    ``minimum_inliers``: fewer agreeing matches and the step is treated as lost."""

    features: int = 1500
    reprojection_error: float = 2.0
    minimum_inliers: int = 30


@dataclass(frozen=True, slots=True, eq=False)
class OdometryStep:
    """``current_from_previous`` maps points of the previous camera frame into the current one."""

    current_from_previous: Pose
    inliers: int
    lost: bool


class VisualOdometry:
    """``step(grey, depth)`` -> the motion since the previous call's frame (identity on the first)."""

    def __init__(self, intrinsics: CameraIntrinsics, config: OdometryConfig | None = None) -> None:
        self.config = config or OdometryConfig()
        self._intrinsics = intrinsics
        self._orb = cv2.ORB_create(nfeatures=self.config.features)
        self._matcher = cv2.BFMatcher(cv2.NORM_HAMMING, crossCheck=True)
        self._previous: tuple[list, np.ndarray, np.ndarray] | None = None

    def step(self, grey: np.ndarray, depth_metres: np.ndarray) -> OdometryStep:
        keypoints, descriptors = self._orb.detectAndCompute(grey, None)
        previous, self._previous = self._previous, (keypoints, descriptors, depth_metres)
        if previous is None:
            return OdometryStep(Pose.identity(), 0, lost=False)
        previous_keypoints, previous_descriptors, previous_depth = previous
        if descriptors is None or previous_descriptors is None:
            return OdometryStep(Pose.identity(), 0, lost=True)
        matches = self._matcher.match(previous_descriptors, descriptors)
        object_points, image_points = [], []
        height, width = previous_depth.shape
        for match in matches:
            u, v = previous_keypoints[match.queryIdx].pt
            column, row = int(round(u)), int(round(v))
            if not (0 <= column < width and 0 <= row < height):
                continue
            z = float(previous_depth[row, column])
            if not np.isfinite(z) or z <= 0.0:
                continue
            object_points.append(self._intrinsics.back_project(np.array(u), np.array(v), np.array(z)))
            image_points.append(keypoints[match.trainIdx].pt)
        if len(object_points) < self.config.minimum_inliers:
            return OdometryStep(Pose.identity(), len(object_points), lost=True)
        found, rotation_vector, translation, inliers = cv2.solvePnPRansac(
            np.array(object_points, dtype=np.float64).reshape(-1, 3),
            np.array(image_points, dtype=np.float64).reshape(-1, 2),
            self._intrinsics.k, None,
            reprojectionError=self.config.reprojection_error, iterationsCount=200, confidence=0.999,
            flags=cv2.SOLVEPNP_EPNP,
        )
        count = 0 if inliers is None else len(inliers)
        if not found or count < self.config.minimum_inliers:
            return OdometryStep(Pose.identity(), count, lost=True)
        index = inliers.reshape(-1)
        rotation_vector, translation = cv2.solvePnPRefineLM(
            np.array(object_points, dtype=np.float64)[index], np.array(image_points, dtype=np.float64)[index],
            self._intrinsics.k, None, rotation_vector, translation,
        )
        rotation, _ = cv2.Rodrigues(rotation_vector)
        return OdometryStep(Pose(rotation, translation.reshape(3)), count, lost=False)
