"""The suite's table: one row per run, hangs and crashes counted wrong, written as markdown and JSON."""

from __future__ import annotations

import json

from merlin2_sailor_demos.report.scenario_table import (
    CRASH,
    HANG,
    ScenarioRun,
    to_markdown,
    to_text,
    write_table,
)
from merlin2_sailor_demos.report.verdict import Verdict

RIGHT = Verdict("found as cup_1", True, (), 0, 2, 88.0, "red_mug")
WRONG = Verdict("found as cup_1", False, ("claimed cup_1, which refers to green_mug, not the red_mug",), 1, 3, 91.0,
                "green_mug", ("cup_2 (confirmed), anchored anew: cup_1 ruled out by colour",))
RUNS = [
    ScenarioRun("default", 0, "rules", RIGHT, wall_seconds=120.0),
    ScenarioRun("removed", 0, "rules", WRONG, wall_seconds=130.0),
    ScenarioRun("swapped", 1, "network", None, ending=HANG, wall_seconds=420.0, note="not done after 420 s"),
    ScenarioRun("twin_moved", 2, "network", None, ending=CRASH, wall_seconds=20.0, note="no scorecard"),
]


def test_each_run_is_one_row_with_its_outcome_verdict_and_figures() -> None:
    lines = to_markdown(RUNS).splitlines()
    assert lines[0] == ("| scenario | seed | matcher | outcome | right/wrong | duplicates | undecided "
                        "| identity switches | time (s) | why wrong |")
    assert lines[2] == "| default | 0 | rules | found as cup_1 | right | 0 | 0 | 2 | 88 |  |"
    assert lines[3].startswith("| removed | 0 | rules | found as cup_1 | WRONG | 1 | 0 | 3 | 91 | claimed cup_1")
    assert lines[4] == "| swapped | 1 | network | hang | WRONG | - | - | - | 420 | not done after 420 s |"
    assert lines[5].startswith("| twin_moved | 2 | network | crash | WRONG |")
    assert lines[7] == "1 of 4 runs right; 1 duplicate anchor(s), 0 left undecided, 5 identity switch(es) in all."
    # Where each duplicate came from, under the table.
    assert lines[-1] == "- removed seed 0 rules: cup_2 (confirmed), anchored anew: cup_1 ruled out by colour"


def test_the_progress_line_says_right_or_wrong_and_why() -> None:
    assert RUNS[0].progress_line(1, 4) == "[1/4] default seed 0 rules: RIGHT (found as cup_1) in 120 s"
    assert RUNS[1].progress_line(2, 4).endswith("WRONG (found as cup_1) in 130 s: claimed cup_1, which refers to "
                                                "green_mug, not the red_mug [duplicate cup_2 (confirmed), anchored "
                                                "anew: cup_1 ruled out by colour]")
    assert "WRONG (hang)" in RUNS[2].progress_line(3, 4)


def test_the_table_is_written_as_markdown_and_json(tmp_path) -> None:
    markdown, data = write_table(tmp_path / "out", RUNS)
    assert markdown.read_text().startswith("# Scenario suite\n\n| scenario |")
    table = json.loads(data.read_text())
    assert (table["right"], table["total"]) == (1, 4)
    first, _, hang, _ = table["runs"]
    assert first["right"] and first["outcome"] == "found as cup_1" and first["verdict"]["identity_switches"] == 2
    assert not hang["right"] and hang["ending"] == HANG and hang["verdict"] is None
    text = to_text(RUNS).splitlines()
    assert text[0].split()[:3] == ["scenario", "seed", "matcher"] and len(text) == 5
