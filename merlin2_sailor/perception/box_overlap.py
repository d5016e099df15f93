"""Box overlap and suppression of one object reported under two classes.

Detectors run non-maximum suppression per class, so a dog can come out both as ``dog`` (0.88)
and ``cat`` (0.48) with the same box. To the anchoring layer that is two objects and would
become two anchors; keeping only the best-scoring class for nearly identical boxes avoids it.
"""

from __future__ import annotations

import numpy as np

from merlin2_sailor.perception.detection import Detection, corners_array


def intersection_over_union(boxes_a: np.ndarray, boxes_b: np.ndarray) -> np.ndarray:
    """Pairwise IoU of (N, 4) and (M, 4) corner boxes, as an (N, M) array (0 for empty boxes)."""
    boxes_a = np.asarray(boxes_a, dtype=np.float64).reshape(-1, 4)
    boxes_b = np.asarray(boxes_b, dtype=np.float64).reshape(-1, 4)
    top_left = np.maximum(boxes_a[:, None, :2], boxes_b[None, :, :2])
    bottom_right = np.minimum(boxes_a[:, None, 2:], boxes_b[None, :, 2:])
    intersection = np.prod(np.clip(bottom_right - top_left, 0.0, None), axis=2)
    area_a = np.prod(np.clip(boxes_a[:, 2:] - boxes_a[:, :2], 0.0, None), axis=1)
    area_b = np.prod(np.clip(boxes_b[:, 2:] - boxes_b[:, :2], 0.0, None), axis=1)
    union = area_a[:, None] + area_b[None, :] - intersection
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(union > 0.0, intersection / union, 0.0)


def suppress_cross_class_duplicates(detections: list[Detection], overlap_threshold: float) -> list[Detection]:
    """Drop a detection when a higher-scoring one of another class covers it with IoU >= threshold.

    Returns the kept detections sorted by decreasing score. Same-class overlaps are left alone:
    the detector's own suppression already handled them, and two people hugging are two people.
    """
    ordered = sorted(detections, key=lambda detection: detection.score, reverse=True)
    overlaps = intersection_over_union(corners_array(ordered), corners_array(ordered))
    kept: list[int] = []
    for candidate, detection in enumerate(ordered):
        duplicate = any(
            overlaps[candidate, better] >= overlap_threshold and ordered[better].class_id != detection.class_id
            for better in kept
        )
        if not duplicate:
            kept.append(candidate)
    return [ordered[index] for index in kept]
