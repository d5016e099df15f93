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
from merlin2_sailor_demos.report.writer import DemoOutcome, truth_from_ground_truth, write_report

__all__ = [
    "AnchorRecord",
    "DemoOutcome",
    "IdentityHistory",
    "MapLayers",
    "Scorecard",
    "TrueObject",
    "associate",
    "draw_map",
    "score",
    "truth_from_ground_truth",
    "write_report",
]
