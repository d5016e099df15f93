"""Turning a matching table into decisions: pure functions of arrays.

The paper runs the Hungarian algorithm on the table (maximising the total score) and accepts
assigned pairs scoring above 0.5. Run literally, a complete assignment can pair a percept with
a poor anchor (below the threshold, so rejected afterwards) *instead of* the good pair that
would have been accepted: the solver must assign min(P, A) pairs and maximises their sum.
Here entries below the threshold weigh nothing (gated pairs hold a negative penalty, so they
always are), which makes the solver return a maximum-weight matching among acceptable pairs:
nobody is forced into a match, and a rejected pair can never displace an acceptable one.

An acceptable pair weighs its score's log-odds over the threshold's, log(s / (1 - s)) -
log(t / (1 - t)), not the score itself: the total is then the log-likelihood ratio of the
assignment against "every percept new", so the solver picks the most probable one. Summing raw
scores instead rewards matching more pairs: where a known object is seen beside one never seen
before (a row of books, the camera turning to show one more), two middling pairs that each hand a
percept to its neighbour's anchor (0.86 + 0.91) outweigh the one near-certain pair (0.999) plus
a new anchor, and the row's anchors slide one object along (measured in `crowded_shelf`, rules,
seed 0, 3 December 2026). In log-odds the near-certain pair wins (6.6 against 1.9 + 2.3).

Tracker ids are evidence applied before that: :func:`apply_tracker_continuity` raises a pair
whose percept continues the anchor's last tracker id to a floor score, but only between the same
class, and never for an empty id.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.optimize import linear_sum_assignment

from merlin2_sailor.errors import InvalidInputError


class Assignment(NamedTuple):
    """``matches``: (M, 2) rows of (percept index, anchor index); the rest are unmatched."""

    matches: np.ndarray
    unmatched_percepts: np.ndarray
    unmatched_anchors: np.ndarray


def assign(table: np.ndarray, threshold: float = 0.5) -> Assignment:
    """Match percepts (rows) to anchors (columns) maximising the total score of accepted pairs.

    A pair is accepted when its score is at or above ``threshold``; everything else is unmatched.
    """
    table = np.asarray(table, dtype=np.float64)
    if table.ndim != 2:
        raise InvalidInputError(f"A matching table must be 2-D (percepts x anchors), got shape {table.shape}.")
    if not (0.0 < threshold <= 1.0):
        raise InvalidInputError(f"The match threshold must be in (0, 1], got {threshold}.")
    if np.isnan(table).any():
        raise InvalidInputError("A matching table must not contain NaN; give impossible pairs a penalty score instead.")
    rows_count, columns_count = table.shape
    acceptable = table >= threshold
    matches = np.zeros((0, 2), dtype=np.intp)
    if acceptable.any():
        # The smallest positive weight keeps a pair scoring exactly the threshold worth taking.
        weights = np.where(acceptable, np.maximum(_log_odds(table) - _log_odds(threshold), _TIE_WEIGHT), 0.0)
        rows, columns = linear_sum_assignment(weights, maximize=True)
        kept = acceptable[rows, columns]
        matches = np.stack((rows[kept], columns[kept]), axis=1).astype(np.intp)
    matched_rows = np.zeros(rows_count, dtype=bool)
    matched_columns = np.zeros(columns_count, dtype=bool)
    matched_rows[matches[:, 0]] = True
    matched_columns[matches[:, 1]] = True
    return Assignment(matches, np.flatnonzero(~matched_rows), np.flatnonzero(~matched_columns))


#: Scores are clipped this far from 0 and 1 before their log-odds are taken (a score of 1 is "certain").
_CLIP = 1e-6
#: The weight of an acceptable pair at the threshold itself: above nothing, below any better pair.
_TIE_WEIGHT = 1e-9


def _log_odds(scores: np.ndarray | float) -> np.ndarray:
    clipped = np.clip(np.asarray(scores, dtype=np.float64), _CLIP, 1.0 - _CLIP)
    return np.log(clipped) - np.log1p(-clipped)


def tracker_continuations(percept_ids: np.ndarray, anchor_ids: np.ndarray) -> np.ndarray:
    """(P, A) bool: the percept's tracker id equals the anchor's last one, and is not empty."""
    percept_ids = np.asarray(percept_ids, dtype=object).reshape(-1, 1)
    anchor_ids = np.asarray(anchor_ids, dtype=object).reshape(1, -1)
    return (percept_ids == anchor_ids) & (percept_ids != "")


def apply_tracker_continuity(
    table: np.ndarray, continues: np.ndarray, same_class: np.ndarray, floor: float
) -> np.ndarray:
    """Raise continuing pairs of the same class to at least ``floor``; returns a new table.

    A tracker follows boxes, not objects: its id can jump to another object after an occlusion,
    so it is evidence to add to M's score, not an identity to trust over a class mismatch.
    """
    raised = np.asarray(continues, dtype=bool) & np.asarray(same_class, dtype=bool)
    return np.where(raised, np.maximum(table, floor), table)
