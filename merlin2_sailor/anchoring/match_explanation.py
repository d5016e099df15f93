"""Why a MISSING anchor took a view: its score, and the best other anchor the view could have gone to.

A missing anchor that takes a view is either its object back or a wrong identity in the making (a
look-alike's views taken by the lost anchor of its twin). Which one cannot be told afterwards
from the anchors alone: the scores of that frame are gone. In `twin_removed_from_the_shelf`
(scenario suite, network, seed 0, 5 December 2026) the removed book's missing anchor took its
twin's views for three frames, 0.3 m from its place, while the twin's own confirmed anchor stood
where the views were, and why the assignment preferred it could not be found. So the event of
such a reacquisition says it, and names every anchor of the view's class standing nearer to it
than the one it went to that the table kept from it, with the reason (held apart or ruled out by
colour, claimed by another view's tracker continuation, out of reach): the twin's anchor of that run
was one, and which rule kept it away was the open question.
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
    from it, its score), or ``"0.83, no other candidate"``. A score that did not read the view's
    look (the matcher's fallback: class, place and time) is marked ``by place``: two bicycles' anchors
    scored 0.89 and 0.27 for one view by how long each had been unseen, and which object the view
    showed could not be read from the line."""
    score = f"{table.scores[row, column]:.2f}{_by_place(table, row, column)}"
    best = best_candidate(table, row, excluded=column)
    if best is None:
        said = f"{score}, no other candidate"
    else:
        anchor = table.anchors[best]
        said = (f"{score} over {anchor.symbol} ({anchor.state.value}, {_distance(table, row, best):.2f} m) "
                f"{table.scores[row, best]:.2f}{_by_place(table, row, best)}")
    kept = kept_from(table, row, column)
    return f"{said}; nearer, kept from it: {kept}" if kept else said


def kept_from(table: MatchingTable, row: int, column: int) -> str:
    """``"cup_4 (confirmed, 0.07 m) held by colour"``: each anchor of the view's class nearer to it
    than the anchor in ``column`` that the table gated for the view, and why (empty: none)."""
    class_name = table.percepts[row].class_name
    reach = _distance(table, row, column)
    said = []
    for other, anchor in enumerate(table.anchors):
        if other == column or anchor.class_name != class_name or not table.gated[row, other]:
            continue
        distance = _distance(table, row, other)
        if distance < reach:
            said.append(f"{anchor.symbol} ({anchor.state.value}, {distance:.2f} m) {_why_gated(table, row, other)}")
    return ", ".join(said)


def _why_gated(table: MatchingTable, row: int, column: int) -> str:
    """The rule of :class:`MatchingTable` that kept a view from an anchor of its class."""
    gap = table.colour_gaps.get((row, column), "")
    gap = f" ({gap})" if gap else ""
    if table.held is not None and table.held[row, column]:
        return f"held apart by a first view of another colour{gap}"
    if table.colour_ruled_out is not None and table.colour_ruled_out[row, column]:
        return f"ruled out by colour{gap}"
    claimed = table.shortcut & table.continuations[:, column]
    claimed[row] = False
    if claimed.any():
        return "claimed by another view's tracker continuation"
    if table.shortcut[row]:
        return "the view continues another anchor's tracker id"
    return "out of reach"


def _by_place(table: MatchingTable, row: int, column: int) -> str:
    if table.by_look is None or table.by_look[row, column]:
        return ""
    return " by place"


def _distance(table: MatchingTable, row: int, column: int) -> float:
    return float(np.linalg.norm(np.asarray(table.percepts[row].position) - table.anchors[column].position))
