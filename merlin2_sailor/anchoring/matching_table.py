"""The matching table, percepts x anchors, built in one batched pass.

The original SAILOR called its network once per (percept, anchor) pair, each call running the
backbone on both crops: cost grew with every anchor ever seen, near or far. Here:

1. **gating before scoring**: a k-d tree over anchor positions (:class:`~.anchor_index.AnchorIndex`)
   returns only anchors within reach of each percept. Reach is
   ``min(base_gate + maximum_speed * time_since_last_seen, maximum_gate)``: an object cannot
   have travelled farther than that since it was last seen. A class mismatch is gated too, when
   configured. Gated pairs are never scored; they hold ``gated_score`` (a penalty below any
   threshold), so the assignment can never pick them;
2. **each crop embedded at most once**: only percepts that still have a pair to score and no
   embedding are embedded, all in one call; the embedding is cached on the returned percept,
   and anchors keep galleries of past embeddings, never re-embedded;
3. **tracker continuity, decided by one rule**: a percept whose (non-empty) tracker id continues
   exactly one CONFIRMED anchor of the same class, last seen at most ``continuation_maximum_age``
   ago, not gated, at most ``continuation_maximum_distance`` from it and not clearly farther
   from it than from another anchor of the class (``continuation_nearest_margin``), is taken as that
   anchor's continuation: its other pairs are not scored
   (which is what spares its crop from the backbone) and the pair scores
   ``tracker_continuity_score``; no other percept of the frame standing farther from that anchor
   may take it (scored against the shortcut's floor, a detector's box across two books, 0.09 m
   from one of them, outbid the book's own view for its anchor, and the book became a new
   anchor), but one standing nearer still may (a look-alike put down beside the object, the
   tracker handing it the object's id). Any other continuing pair of the same class is raised to
   that floor; a class mismatch never is;
4. **one vectorised feature computation and one matcher call** for all remaining pairs;
5. **appearance only from comparable views**: a partial view's crop is not compared with an
   anchor's views (:func:`.partial_view.comparable_views`), nor embedded for it;
6. **colour evidence**: a whole view whose colour rules out an anchor unseen for a while (a
   look-alike of another colour put in its place) is gated from it, whatever the matcher scored,
   when the anchor's own views of about that view's size say so
   (:func:`~.colour_evidence.sized_view_differs`) and a first such view a moment earlier did too;
   that first view is only held apart from the anchor (``held``). A view is whole *for an anchor*
   as appearance takes it (:func:`.partial_view.comparable_views`): a view showing clearly less of
   a large object than the anchor's whole views did has a part's colour, not the object's; and
   only where the view and the anchor's views show about as much of a large object's height and
   footprint, whichever saw less (:func:`.partial_view.colour_comparable_views`).
   A view anywhere in the disc of a search for an anchor (which the table counts as in place)
   is gated from it when its colour differs from the anchor's mean over all its views, as a
   search's merge of two anchors asks (:func:`~.colour_evidence.view_differs`): a white mug 2 m
   from the middle of the searched bedroom, never anchored, had taken the lost blue mug's symbol
   on its first view (scenario suite, `moved_while_its_twin_is_watched`, network, seed 0,
   5 December 2026).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from merlin2_sailor.anchoring.anchor import Anchor, AnchorState, view_bearing, view_scale
from merlin2_sailor.anchoring.anchor_index import AnchorIndex
from merlin2_sailor.anchoring.assignment import apply_tracker_continuity, tracker_continuations
from merlin2_sailor.anchoring.colour_evidence import (
    ColourEvidenceConfig,
    sized_view_differs,
    view_differs,
    view_gap_text,
)
from merlin2_sailor.anchoring.features import AnchorColumns, PerceptColumns, extent_slack, pair_features
from merlin2_sailor.anchoring.matcher import Matcher
from merlin2_sailor.anchoring.partial_view import colour_comparable_views, comparable_views
from merlin2_sailor.contract.percept import Percept
from merlin2_sailor.errors import ConfigurationError


class Embedder(Protocol):
    """Anything that embeds crops, like :class:`merlin2_sailor.perception.embedding.CropEmbedder`."""

    def embed(self, crops: Sequence[np.ndarray]) -> np.ndarray: ...


@dataclass(frozen=True, slots=True)
class MatchingTableConfig:
    """``base_gate`` (m): reach of an anchor seen just now (depth noise plus a nudge);
    ``maximum_speed`` (m/s): how fast an unseen object may plausibly have been moved;
    ``maximum_gate`` (m): the reach's cap, so that long-unseen anchors do not become candidates
    for every percept in the house (beyond 5 m the distance feature exp(-d) is below 0.007: it
    says "elsewhere" either way, and a pair there could only match on appearance, which objects
    of one class often share); ``gate_class_mismatch``: never pair different classes;
    ``tracker_continuity_score``: the floor for a pair continuing a tracker id;
    ``continuation_maximum_age`` (s): how recent a continued anchor must be to skip scoring
    (about a tracker's buffer); ``continuation_maximum_distance`` (m): how far from a continued
    anchor a percept may be for its tracker id to count at all (a 2D tracker swaps ids between
    nearby objects of one class when the camera turns fast: an id that lands half a metre or more
    away is a swap, not the same object); ``continuation_nearest_margin`` (m): an id does not count
    either when another anchor of the class is nearer the percept than the continued one by more
    than this (the id swapped to a neighbour); ``gated_score``: the penalty gated pairs hold (negative);
    ``search_score_cap``: the most a pair with an anchor being searched for (an expectation with a
    radius) can score, below an in-place match and a tracker continuation, so that a look-alike
    anchored where the search looks keeps its own percept."""

    base_gate: float = 3.0
    maximum_speed: float = 0.25
    maximum_gate: float = 5.0
    gate_class_mismatch: bool = True
    tracker_continuity_score: float = 0.9
    continuation_maximum_age: float = 1.0
    continuation_maximum_distance: float = 0.5
    continuation_nearest_margin: float = 0.1
    gated_score: float = -1.0
    search_score_cap: float = 0.7

    def __post_init__(self) -> None:
        if not (math.isfinite(self.base_gate) and self.base_gate > 0.0):
            raise ConfigurationError(f"table base_gate must be a positive number of metres, got {self.base_gate}.")
        if not (math.isfinite(self.maximum_speed) and self.maximum_speed >= 0.0):
            raise ConfigurationError(f"table maximum_speed must be >= 0 m/s, got {self.maximum_speed}.")
        if not (math.isfinite(self.maximum_gate) and self.maximum_gate >= self.base_gate):
            raise ConfigurationError(
                f"table maximum_gate ({self.maximum_gate}) must be finite and at least base_gate ({self.base_gate})."
            )
        if not (0.0 < self.tracker_continuity_score <= 1.0):
            raise ConfigurationError(
                f"table tracker_continuity_score must be in (0, 1], got {self.tracker_continuity_score}."
            )
        if not (math.isfinite(self.continuation_maximum_age) and self.continuation_maximum_age >= 0.0):
            raise ConfigurationError(
                f"table continuation_maximum_age must be >= 0 seconds, got {self.continuation_maximum_age}."
            )
        if not (0.0 < self.search_score_cap <= 1.0):
            raise ConfigurationError(f"table search_score_cap must be in (0, 1], got {self.search_score_cap}.")
        if not (math.isfinite(self.continuation_nearest_margin) and self.continuation_nearest_margin >= 0.0):
            raise ConfigurationError(
                f"table continuation_nearest_margin must be >= 0 metres, got {self.continuation_nearest_margin}."
            )
        if not (math.isfinite(self.continuation_maximum_distance) and self.continuation_maximum_distance > 0.0):
            raise ConfigurationError(
                f"table continuation_maximum_distance must be a positive number of metres, "
                f"got {self.continuation_maximum_distance}."
            )
        if not self.gated_score < 0.0:
            raise ConfigurationError(f"table gated_score must be negative (below any score), got {self.gated_score}.")


@dataclass(frozen=True, slots=True, eq=False)
class MatchingTable:
    """Scores of every percept against the anchors that pass the gate for at least one percept.

    ``percepts`` are the inputs with any embedding computed here cached on them; ``anchors`` are
    the columns (an anchor gated for every percept is not a column at all); ``scores`` hold
    ``gated_score`` where ``gated``; ``continuations`` marks pairs raised by tracker continuity,
    ``shortcut`` the percepts taken as continuations without scoring; ``embedded`` counts the crops
    embedded while building the table.
    """

    percepts: tuple[Percept, ...]
    anchors: tuple[Anchor, ...]
    scores: np.ndarray
    gated: np.ndarray
    continuations: np.ndarray
    shortcut: np.ndarray
    embedded: int = 0
    disputed: tuple[Anchor, ...] = ()
    """Anchors a whole view of another colour was ruled out from (see :mod:`.colour_evidence`)."""
    colour_ruled_out: np.ndarray | None = None
    """(P, A) bool: the pairs gated by colour (None: no colour was asked), for the acquired event's
    account of why a view got a new anchor."""
    suspected: tuple[Anchor, ...] = ()
    """Anchors a first whole view of another colour raised a suspicion about (see :mod:`.colour_evidence`)."""
    held: np.ndarray | None = None
    """(P, A) bool: the pairs such a first view held apart: gated too, and the view, unless another
    anchor takes it, is left unresolved rather than anchored anew (None: no colour was asked)."""
    colour_gaps: Mapping[tuple[int, int], str] = dataclasses.field(default_factory=dict)
    """{(row, column): how the view's colour differed} for the pairs held apart or ruled out by a
    view of another colour (:func:`~.colour_evidence.view_gap_text`), for the log."""
    by_look: np.ndarray | None = None
    """(P, A) bool: the scored pairs whose score read the view's look against the anchor's (None: the
    matcher reads no look); elsewhere a score is the matcher's fallback (class, place and time), which
    the log says, since it is no evidence of which of two objects of a class a view shows."""


class MatchingTableBuilder:
    """Builds :class:`MatchingTable` s with one matcher, one configuration, one optional embedder."""

    def __init__(
        self, matcher: Matcher, config: MatchingTableConfig | None = None, embedder: Embedder | None = None,
        colour: ColourEvidenceConfig | None = None,
    ) -> None:
        self.matcher = matcher
        self.config = config or MatchingTableConfig()
        self.embedder = embedder
        self.colour = colour or ColourEvidenceConfig()

    def gate_radius(self, elapsed: np.ndarray | float) -> np.ndarray:
        """How far an anchor unseen for ``elapsed`` seconds may be from a percept of it."""
        elapsed = np.maximum(np.asarray(elapsed, dtype=np.float64), 0.0)
        return np.minimum(self.config.base_gate + self.config.maximum_speed * elapsed, self.config.maximum_gate)

    def build(
        self, percepts: Sequence[Percept], index: AnchorIndex, whole: Sequence[bool] | None = None
    ) -> MatchingTable:
        """``whole``: per percept, whether it shows its whole object (None: not known), so that
        its colour may count as evidence."""
        percepts = tuple(percepts)
        columns = PerceptColumns.from_percepts(percepts)
        pair_rows, pair_slots = self._ungated_pairs(columns, index)
        if pair_slots.size == 0:
            return self._empty(percepts)
        slots, pair_columns = np.unique(pair_slots, return_inverse=True)
        anchors = tuple(index.anchors_at(slots))
        anchor_columns = AnchorColumns.from_anchors(anchors)
        shape = (len(percepts), len(anchors))
        gated = np.ones(shape, dtype=bool)
        gated[pair_rows, pair_columns] = False

        same_class = columns.class_names[:, np.newaxis] == anchor_columns.class_names[np.newaxis, :]
        continuations = tracker_continuations(columns.tracker_ids, anchor_columns.tracker_ids) & same_class & ~gated
        candidate_rows, candidate_columns = np.nonzero(continuations)
        distance = np.linalg.norm(
            columns.positions[:, np.newaxis, :] - anchor_columns.positions[np.newaxis, :, :], axis=2
        ) if candidate_rows.size else None
        if distance is not None:
            jump = distance[candidate_rows, candidate_columns]
            too_far = jump > self.config.continuation_maximum_distance
            # An id that lands on an object while another of its class lies clearly nearer the
            # percept has swapped between neighbours (books on a shelf, as the camera turns).
            nearest = np.where(same_class & ~gated, distance, np.inf)[candidate_rows].min(axis=1)
            swapped = jump > nearest + self.config.continuation_nearest_margin
            not_continued = too_far | swapped
            continuations[candidate_rows[not_continued], candidate_columns[not_continued]] = False
        confirmed = np.array([anchor.state is AnchorState.CONFIRMED for anchor in anchors], dtype=bool)
        age = columns.stamps[:, np.newaxis] - anchor_columns.last_seen[np.newaxis, :]
        eligible = continuations & confirmed[np.newaxis, :] & (age <= self.config.continuation_maximum_age)
        shortcut = eligible.sum(axis=1) == 1
        gated[shortcut] = ~eligible[shortcut]
        if distance is not None:  # a continued anchor is claimed from views no nearer to it
            for row, column in zip(*np.nonzero(eligible & shortcut[:, np.newaxis]), strict=True):
                gated[~shortcut & (distance[:, column] >= distance[row, column]), column] = True
        continuations &= ~gated

        to_score = ~gated & ~shortcut[:, np.newaxis]
        comparable, embedded, by_look = None, 0, None
        if self.matcher.uses_appearance:  # only a matcher that reads the look needs to know which views show it
            comparable = comparable_views(columns.sizes, whole, anchors)
            percepts, embedded = self._embed_needed(percepts, np.flatnonzero((to_score & comparable).any(axis=1)))
            if embedded:
                columns = PerceptColumns.from_percepts(percepts)

        scores = np.full(shape, self.config.gated_score)
        rows, score_columns = np.nonzero(to_score)
        if rows.size:
            features = pair_features(
                columns, anchor_columns, rows, score_columns, self.matcher.feature_config, self.matcher.uses_appearance
            )
            if comparable is not None:
                features = dataclasses.replace(
                    features, appearance_known=features.appearance_known & comparable[rows, score_columns])
                by_look = np.zeros(shape, dtype=bool)
                by_look[rows, score_columns] = features.appearance_known
            scores[rows, score_columns] = self.matcher.score_pairs(features)
        if anchor_columns.search_radii is not None:
            searched = (anchor_columns.search_radii > 0.0)[np.newaxis, :] & to_score
            scores[searched] = np.minimum(scores[searched], self.config.search_score_cap)
        scores[shortcut] = np.where(eligible[shortcut], self.config.tracker_continuity_score, self.config.gated_score)
        scores = apply_tracker_continuity(scores, continuations, same_class, self.config.tracker_continuity_score)
        disputed: tuple[Anchor, ...] = ()
        suspected: tuple[Anchor, ...] = ()
        ruled_out = held = None
        colour_gaps: dict[tuple[int, int], str] = {}
        if whole is not None:
            # Held to each anchor as appearance is: a part of a large object (a view measuring 0.59 m
            # of a bicycle's 1.68 m) showed another colour than the whole bicycle's views and ruled
            # its anchor out, one object under two symbols (scenario suite, `twin_moved`, network,
            # seed 0, 5 December 2026).
            # Nor is a view held to an anchor that saw more or less of the object's height or length
            # than it did (:func:`.partial_view.colour_comparable_views`).
            whole_for = colour_comparable_views(columns.sizes, whole, anchors, comparable)
            ruled_out, differing, held, colour_gaps = self._ruled_out_by_colour(percepts, anchors, whole_for, ~gated)
            apart = ruled_out | held
            scores[apart] = self.config.gated_score
            gated |= apart
            continuations &= ~apart
            disputed = tuple(anchors[column] for column in np.flatnonzero(differing.any(axis=0)))
            suspected = tuple(anchors[column] for column in np.flatnonzero(held.any(axis=0)))
            if anchor_columns.search_radii is not None:
                searched_apart = self._searched_another_colour(
                    percepts, anchors, whole_for, ~gated & (anchor_columns.search_radii > 0.0)[np.newaxis, :])
                scores[searched_apart] = self.config.gated_score
                gated |= searched_apart
                continuations &= ~searched_apart
                ruled_out |= searched_apart
        return MatchingTable(percepts, anchors, scores, gated, continuations, shortcut, embedded, disputed, ruled_out,
                             suspected, held, colour_gaps, by_look)

    def _ungated_pairs(self, percepts: PerceptColumns, index: AnchorIndex) -> tuple[np.ndarray, np.ndarray]:
        """(rows, slots) of the pairs that pass the gate, computed on the index's arrays only.

        The k-d tree is asked for the largest reach any anchor can have now; each candidate is then
        held to its own reach (and class), so only the anchors that pass become Python objects.
        """
        empty = np.zeros(0, dtype=np.intp)
        if len(percepts.stamps) == 0 or len(index) == 0:
            return empty, empty
        radius = float(self.gate_radius(float(percepts.stamps.max()) - index.oldest_last_seen()))
        percept_slacks = extent_slack(percepts.sizes)
        radius += index.largest_search_radius() + index.largest_extent_slack() + float(np.max(percept_slacks))
        per_row = index.within(percepts.positions, radius)
        rows = np.repeat(np.arange(len(per_row), dtype=np.intp), [len(slots) for slots in per_row])
        if rows.size == 0:
            return empty, empty
        slots = np.concatenate(per_row).astype(np.intp)
        distance = np.linalg.norm(percepts.positions[rows] - index.positions_of(slots), axis=1)
        reach = (self.gate_radius(percepts.stamps[rows] - index.last_seen_of(slots)) + index.search_radii_of(slots)
                 + np.maximum(index.extent_slacks_of(slots), percept_slacks[rows]))
        passing = distance <= reach
        if self.config.gate_class_mismatch:
            passing &= percepts.class_names[rows] == index.class_names_of(slots)
        return rows[passing], slots[passing]

    def _ruled_out_by_colour(
        self, percepts: tuple[Percept, ...], anchors: tuple[Anchor, ...], whole: np.ndarray, open_pairs: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict[tuple[int, int], str]]:
        """(ruled out, differing, held, gaps), the first three (P, A): the pairs gated by colour; among them those
        whose percept, a whole view (``whole``: (P, A), of the anchor's object) with a colour
        standing in the anchor's place, differed from an
        anchor whose colour had gone unchecked for the configured absence (or was disputed
        already) and confirmed a suspicion
        a first such view raised (the others ruled out are views without a colour, far or cut
        off, of what stands where a disputed anchor was); and the pairs of a view that differed
        but only raised the suspicion; ``gaps`` says, for the last two, how the colour differed."""
        ruled_out = np.zeros(open_pairs.shape, dtype=bool)
        differing = np.zeros(open_pairs.shape, dtype=bool)
        held = np.zeros(open_pairs.shape, dtype=bool)
        gaps: dict[tuple[int, int], str] = {}
        if self.colour.minimum_views == 0 or not any(a.colour is not None or a.colour_disputed for a in anchors):
            return ruled_out, differing, held, gaps  # no anchor has a colour to tell by: spare the loop over pairs
        in_place = self._in_place(percepts, anchors)
        for row, column in zip(*np.nonzero(open_pairs), strict=True):
            percept, anchor = percepts[row], anchors[column]
            if whole[row, column] and percept.colour is not None and not anchor.colour_untellable(percept, self.colour):
                if in_place[row, column] and anchor.colour_unchecked(percept.stamp, self.colour) and sized_view_differs(
                        anchor.colour_by_size, percept.colour, view_scale(percept), self.colour, view_bearing(percept)):
                    confirmed = anchor.colour_disputed or self.colour.suspicion_confirmed(
                        anchor.colour_suspected, percept.stamp)
                    differing[row, column] = confirmed
                    held[row, column] = not confirmed
                    gaps[row, column] = view_gap_text(anchor.colour_by_size, percept.colour, view_scale(percept),
                                                      self.colour, view_bearing(percept))
                ruled_out[row, column] = differing[row, column]
            else:
                # Nothing coloured has been its colour there since: a view without a colour, or with
                # one that cannot be held to the anchor's, is no way back.
                ruled_out[row, column] = anchor.colour_disputed and anchor.state is AnchorState.MISSING
        return ruled_out, differing, held, gaps

    def _searched_another_colour(
        self, percepts: tuple[Percept, ...], anchors: tuple[Anchor, ...], whole: np.ndarray, open_pairs: np.ndarray,
    ) -> np.ndarray:
        """(P, A) bool: the pairs (among ``open_pairs``, those with a searched anchor) of a whole
        view whose colour differs from the anchor's over all its views (see the module docstring)."""
        apart = np.zeros(open_pairs.shape, dtype=bool)
        if self.colour.minimum_views == 0:
            return apart
        for row, column in zip(*np.nonzero(open_pairs & whole), strict=True):
            apart[row, column] = view_differs(anchors[column].colour, percepts[row].colour, self.colour)
        return apart

    def _in_place(self, percepts: tuple[Percept, ...], anchors: tuple[Anchor, ...]) -> np.ndarray:
        """(P, A) bool: the percept stands in the anchor's place: within ``place_radius``
        horizontally, and no neighbour of the anchor's class is nearer to it (on a shelf, a book's
        view is its own anchor's, not its neighbour's place). A neighbour is an anchor that already
        existed when the anchor's colour was last checked: one born since, perhaps of the very
        object in its place (a look-alike anchored there once ruled out), is no neighbour."""
        positions = np.array([percept.position[:2] for percept in percepts], dtype=np.float64).reshape(-1, 2)
        places = np.array([anchor.position[:2] for anchor in anchors], dtype=np.float64).reshape(-1, 2)
        distance = np.linalg.norm(positions[:, np.newaxis, :] - places[np.newaxis, :, :], axis=2)
        classes = np.array([anchor.class_name for anchor in anchors], dtype=object)
        born = np.array([anchor.first_seen for anchor in anchors], dtype=np.float64)
        checked = np.array([anchor.colour_seen if anchor.colour_seen is not None else anchor.last_seen
                            for anchor in anchors], dtype=np.float64)
        # neighbour[k, a]: anchor k is a neighbour of anchor a
        neighbour = (classes[:, np.newaxis] == classes[np.newaxis, :]) & (born[:, np.newaxis] <= checked[np.newaxis, :])
        np.fill_diagonal(neighbour, False)
        nearest_neighbour = np.where(neighbour[np.newaxis, :, :], distance[:, :, np.newaxis], np.inf).min(axis=1)
        return (distance <= self.colour.place_radius) & (distance <= nearest_neighbour)

    def _embed_needed(self, percepts: tuple[Percept, ...], rows: np.ndarray) -> tuple[tuple[Percept, ...], int]:
        """Embed, in one call, the crops of the given percepts that have none yet."""
        if not self.matcher.uses_appearance or self.embedder is None:
            return percepts, 0
        needed = [int(row) for row in rows if percepts[row].embedding is None and percepts[row].crop.size > 0]
        if not needed:
            return percepts, 0
        return with_embeddings(percepts, needed, self.embedder), len(needed)

    def _empty(self, percepts: tuple[Percept, ...]) -> MatchingTable:
        empty = np.zeros((len(percepts), 0))
        return MatchingTable(
            percepts, (), empty, empty.astype(bool), empty.astype(bool), np.zeros(len(percepts), dtype=bool)
        )


def held_views(table: MatchingTable, unmatched: Sequence[int], unresolved: Mapping[int, Anchor]) -> dict[int, Anchor]:
    """{percept row: the anchor it was held apart from} for the ``unmatched`` percepts a first view
    of another colour held (not already ``unresolved``): neither that anchor's nor a new one's yet."""
    if table.held is None:
        return {}
    return {row: table.anchors[int(np.argmax(table.held[row]))]
            for row in unmatched if row not in unresolved and table.held[row].any()}


def with_embeddings(percepts: tuple[Percept, ...], rows: Sequence[int], embedder: Embedder) -> tuple[Percept, ...]:
    """Return the percepts with the crops at ``rows`` embedded (one batched call) and cached on them."""
    features = np.asarray(embedder.embed([percepts[row].crop for row in rows]), dtype=np.float32)
    updated = list(percepts)
    for row, feature in zip(rows, features, strict=True):
        updated[row] = dataclasses.replace(percepts[row], embedding=feature)
    return tuple(updated)
