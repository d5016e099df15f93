"""Anchors not seen this frame: which should have been (and so count towards MISSING, or have an
expected place seen empty), and which have been missing long enough to forget.

Not seeing an object proves nothing unless the camera could have seen it: only anchors inside
the frustum and not hidden behind nearer depth (:mod:`.visibility`) count. A search is never
retracted by an empty view: the searcher cannot know which part of its disc the camera covered.
"""

from __future__ import annotations

import math
from collections.abc import Set

import numpy as np

from merlin2_sailor.anchoring.anchor import Anchor
from merlin2_sailor.anchoring.anchor_index import AnchorIndex
from merlin2_sailor.anchoring.events import AnchorEventKind
from merlin2_sailor.anchoring.frame_changes import FrameChanges
from merlin2_sailor.anchoring.lifecycle import LifecycleConfig, after_expected_but_unseen, expire
from merlin2_sailor.anchoring.observation import drop_expectation
from merlin2_sailor.anchoring.visibility import CameraView, VisibilityConfig, should_be_visible


def check_unseen(
    index: AnchorIndex, camera: CameraView, seen: Set[str], changes: FrameChanges,
    visibility: VisibilityConfig, lifecycle: LifecycleConfig,
) -> None:
    """Count anchors that should have been seen but were not; retract expectations seen empty."""
    slots = index.within(camera.position.reshape(1, 3), frustum_reach(camera, visibility))[0]
    anchors = [anchor for anchor in index.anchors_at(slots) if anchor.symbol not in seen]
    if not anchors:
        return
    visible = should_be_visible(
        np.array([a.position for a in anchors]), np.array([a.size for a in anchors]), camera, visibility
    )
    for anchor in (a for a, expected in zip(anchors, visible, strict=True) if expected):
        if anchor.expectation is not None and anchor.expectation.is_search:
            continue  # the searcher decides when a search has failed
        if anchor.expectation is not None:
            changes.event(
                AnchorEventKind.RETRACTED, anchor.symbol, reason="expected place seen empty",
                expectation=anchor.expectation.describe(),
            )
            drop_expectation(anchor)
            anchor.position = anchor.perceived_position.copy()
            index.refresh(anchor)
        elif after_expected_but_unseen(anchor, changes.stamp, lifecycle):
            changes.missing.append(anchor)
            changes.event(AnchorEventKind.MISSING, anchor.symbol, missed_frames=anchor.missed_frames)


def forget_expired(index: AnchorIndex, changes: FrameChanges, lifecycle: LifecycleConfig) -> list[Anchor]:
    """Forget anchors missing (or, never confirmed, unseen where expected) for too long."""
    forgotten = []
    for anchor in index.on_the_forgetting_clock():
        if expire(anchor, changes.stamp, lifecycle):
            index.remove(anchor.symbol)
            anchor.visible = False
            forgotten.append(anchor)
            changes.forgotten.append(anchor)
            changes.event(
                AnchorEventKind.FORGOTTEN, anchor.symbol, reason="missing too long", missing_since=anchor.missing_since
            )
    return forgotten


def frustum_reach(camera: CameraView, config: VisibilityConfig) -> float:
    """The largest distance from the optical centre of any point inside the frustum."""
    intrinsics = camera.intrinsics
    half_width = max(intrinsics.cx, intrinsics.width - intrinsics.cx) / intrinsics.fx
    half_height = max(intrinsics.cy, intrinsics.height - intrinsics.cy) / intrinsics.fy
    return config.frustum.far * math.sqrt(1.0 + half_width**2 + half_height**2)
