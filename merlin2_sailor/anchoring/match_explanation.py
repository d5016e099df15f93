"""Why a MISSING anchor took a view: its score, and the best other anchor the view could have gone to.

A missing anchor that takes a view is either its object back or a wrong identity in the making (a
look-alike's views taken by the lost anchor of its twin). Which one cannot be told afterwards
from the anchors alone: the scores of that frame are gone. In `twin_removed_from_the_shelf`
(scenario suite, network, seed 0, 5 December 2026) the removed book's missing anchor took its
twin's views for three frames, 0.3 m from its place, while the twin's own confirmed anchor stood
where the views were, and why the assignment preferred it could not be found. So the event of
such a reacquisition says it.
"""

from __future__ import annotations

import numpy as np

from merlin2_sailor.anchoring.matching_table import MatchingTable


def best_candidate(table: MatchingTable, row: int, excluded: int | None = None) -> int | None:
    """The column of the anchor of the view's class that passed the gate for it with the best
    score, leaving out ``excluded``; None when there is none."""
    class_name = table.percepts[row].class_name
    columns = [column for column, anchor in enumerate(table.anchors)
               if column != excluded and not table.gated[row, column] and anchor.class_name == class_name]
    return max(columns, key=lambda column: table.scores[row, column]) if columns else None


def matched_over(table: MatchingTable, row: int, column: int) -> str:
    """``"0.83 over cup_4 (confirmed, 0.31 m) 0.79"``: the pair's score, then the best other
    anchor of the view's class that passed the gate for it (its state, how far the view stands
    from it, its score), or ``"0.83, no other candidate"``."""
    percept = table.percepts[row]
    score = f"{table.scores[row, column]:.2f}"
    best = best_candidate(table, row, excluded=column)
    if best is None:
        return f"{score}, no other candidate"
    anchor = table.anchors[best]
    distance = float(np.linalg.norm(np.asarray(percept.position) - anchor.position))
    return f"{score} over {anchor.symbol} ({anchor.state.value}, {distance:.2f} m) {table.scores[row, best]:.2f}"
