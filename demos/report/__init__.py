"""The mission demo's report: a scorecard against the world's ground truth and a top-down map.

ROS-free: both take plain data (true objects, anchors, facts), so they also score a run recorded
elsewhere.
"""

from merlin2_sailor_demos.report.scorecard import (
    AnchorRecord,
    IdentityHistory,
    Scorecard,
    TrueObject,
    associate,
    score,
)
from merlin2_sailor_demos.report.top_down_map import MapLayers, draw_map

__all__ = [
    "AnchorRecord",
    "IdentityHistory",
    "MapLayers",
    "Scorecard",
    "TrueObject",
    "associate",
    "draw_map",
    "score",
]
