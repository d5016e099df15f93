"""The mission demo's report: a scorecard against the world's ground truth and a top-down map,
the verdict on the mission's claims, and the scenario suite's table.

ROS-free: all take plain data (true objects, anchors, facts, scorecard.json), so they also score
a run recorded elsewhere.
"""

from merlin2_sailor_demos.report.scenario_table import ScenarioRun, write_table
from merlin2_sailor_demos.report.scorecard import (
    AnchorRecord,
    IdentityHistory,
    Scorecard,
    TrueObject,
    associate,
    score,
)
from merlin2_sailor_demos.report.top_down_map import MapLayers, draw_map
from merlin2_sailor_demos.report.truth_timeline import TruthTimeline, refers_to
from merlin2_sailor_demos.report.verdict import Verdict, judge
from merlin2_sailor_demos.report.writer import DemoOutcome, truth_from_ground_truth, write_report

__all__ = [
    "AnchorRecord",
    "DemoOutcome",
    "IdentityHistory",
    "MapLayers",
    "ScenarioRun",
    "Scorecard",
    "TrueObject",
    "TruthTimeline",
    "Verdict",
    "associate",
    "draw_map",
    "judge",
    "refers_to",
    "score",
    "truth_from_ground_truth",
    "write_report",
    "write_table",
]
