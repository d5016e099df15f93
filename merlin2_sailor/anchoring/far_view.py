"""A view too far to tell: left unresolved instead of becoming a new anchor.

Why. An appearance matcher compares a percept's crop with the anchor's gallery of recent views.
When the percept's box is much smaller than every view the gallery holds (the object seen again
from across a room, after close views), its crop is a blurred, upsampled copy of what the
gallery saw sharp, and the comparison says little. Measured on the 10 held-out houses of the
house source (3 December 2026, same-class pairs of Algorithm 3, the shipped weights): where the
percept's box is under half the size of the anchor's largest view, the network rejects 5.7-6.8 %
of true pairs against 1.4-1.9 % at comparable sizes, and replaying the houses through the
anchoring layer, 10 of the network's 16 split objects were such views of an object at its own
place (0.08-0.17 m) after 10-94 s away, scored 0.09-0.47. In the simulated house the same thing
made the hall mug a second anchor, on its own spot, as the robot left the hall
(`lookalike_added`, seed 0): a look-alike added beside it later took the first symbol.

What it does. An unmatched whole view (a partial one is scored without its look anyway) is
*unresolved* (no anchor acquired, its symbol empty) when an anchor of its class that no percept
of this frame reacquired scored it at least ``score_floor`` (not a firm "another object") and
every view in that anchor's gallery is more than ``1 / scale_ratio`` times the percept's size.
The anchor is then not counted as unseen in that frame either (something of its class stood
where it was; whether it was the anchor could not be told). A closer view decides: matched, it is
reacquired; rejected at a comparable size, it becomes a new anchor. Nothing is guessed: a
removed or replaced object seen only from afar is neither reported found nor anchored anew, it
stays unknown until a view can tell. A firm rejection (below ``score_floor``) is acted on at any
size, and a matcher without appearance (the rules, whose anchors have no gallery) is never
affected.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.anchoring.anchor import Anchor, view_scale
from merlin2_sailor.anchoring.gallery import view_scales
from merlin2_sailor.anchoring.match_explanation import best_candidate
from merlin2_sailor.anchoring.matching_table import MatchingTable
from merlin2_sailor.errors import ConfigurationError


@dataclass(frozen=True, slots=True)
class FarViewConfig:
    """``scale_ratio``: a view is far from an anchor's views when its size (square root of its box's
    area, pixels) is under this share of every view in the anchor's gallery (0 turns the whole
    mechanism off); ``score_floor``: a matching score below it is a firm "another object",
    acted on whatever the view's size."""

    scale_ratio: float = 0.5
    score_floor: float = 0.05

    def __post_init__(self) -> None:
        if not (math.isfinite(self.scale_ratio) and 0.0 <= self.scale_ratio < 1.0):
            raise ConfigurationError(f"far_view scale_ratio must be in [0, 1), got {self.scale_ratio}.")
        if not (math.isfinite(self.score_floor) and 0.0 <= self.score_floor < 1.0):
            raise ConfigurationError(f"far_view score_floor must be in [0, 1), got {self.score_floor}.")


def unresolved_far_views(
    table: MatchingTable, unmatched: Sequence[int], taken: np.ndarray, partial: Sequence[bool],
    match_threshold: float, config: FarViewConfig,
) -> dict[int, Anchor]:
    """{percept row: the anchor it may be} for the ``unmatched`` percepts too far to tell from an
    anchor that no percept reacquired (``taken``: (A,) bool, the table's columns reacquired).

    A ``partial`` view is scored without its look already (:func:`.partial_view.comparable_views`):
    its score says what place and time say, at any size, so it is judged as it is."""
    rows = [row for row in unmatched if not partial[row]]
    if config.scale_ratio <= 0.0 or not rows or not table.anchors:
        return {}
    classes = np.array([anchor.class_name for anchor in table.anchors], dtype=object)
    smallest = np.array([smallest_view(anchor) for anchor in table.anchors])
    unresolved: dict[int, Anchor] = {}
    for row in rows:
        percept = table.percepts[row]
        scores = table.scores[row]
        candidates = (~taken & ~table.gated[row] & (classes == percept.class_name)
                      & (scores >= config.score_floor) & (scores < match_threshold)
                      & (0.0 < view_scale(percept)) & (view_scale(percept) < config.scale_ratio * smallest))
        if candidates.any():
            unresolved[int(row)] = table.anchors[int(np.argmax(np.where(candidates, scores, -np.inf)))]
    return unresolved


def smallest_view(anchor: Anchor) -> float:
    """The size of the smallest view in the anchor's gallery; 0 when any is unknown or there is
    none (nothing then says the percept is far from all of them)."""
    scales = view_scales(anchor.gallery, anchor.gallery_scales)
    return 0.0 if len(scales) == 0 or np.isnan(scales).any() else float(scales.min())


def nearest_anchor(table: MatchingTable, row: int, taken: np.ndarray) -> str:
    """The anchor of the percept's class that scored it best, with the score, how the view's size
    compares with that anchor's views, and whether another view of the frame took it (``taken``:
    (A,) bool, the columns reacquired): why a new anchor was made, for the acquired event (a
    duplicate's first question), then the anchors its colour ruled out (even when another anchor
    scored it: the one it stood in the place of is the one that matters). Empty when no anchor of
    its class passed the gate and none was ruled out."""
    percept = table.percepts[row]
    column = best_candidate(table, row)
    # Gated by colour: the view's colour ruled out an anchor whose own went unchecked a while.
    ruled_out = table.colour_ruled_out
    by_colour = [] if ruled_out is None else sorted(
        (table.anchors[column].symbol, table.colour_gaps.get((row, int(column)), ""))
        for column in np.flatnonzero(ruled_out[row]))
    colour_text = ", ".join(f"{symbol} ruled out by colour" + (f" ({gap})" if gap else "")
                            for symbol, gap in by_colour)
    if column is None:
        return colour_text
    anchor = table.anchors[column]
    text = f"{anchor.symbol} scored {table.scores[row, column]:.2f}"
    smallest = smallest_view(anchor)
    if smallest > 0.0:
        text += f", view {view_scale(percept) / smallest:.2f} of its smallest"
    if taken[column]:
        text += ", taken by another view"
    return f"{text}; {colour_text}" if colour_text else text
