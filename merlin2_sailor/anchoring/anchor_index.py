"""The live anchors, indexed by symbol and by position, so that far anchors cost nothing.

Matching gates out anchors too far from a percept, and visibility only concerns anchors near the
camera; both ask "which anchors are within r of these points?". A k-d tree
(``scipy.spatial.cKDTree``) answers that in time that depends on the anchors nearby, not on how
many exist. A cKDTree cannot be updated in place, and rebuilding it every frame would cost
O(A log A), so the index keeps the tree *loosely*:

- positions are indexed as they were when the tree was built; an anchor that has moved less than
  ``tolerance`` since is still found, because queries search ``tolerance`` further and then
  filter on current positions (fusion moves anchors by centimetres, so this is the usual case);
- anchors added, or moved farther than ``tolerance``, wait in a small *pending* set that every
  query checks by brute force;
- the tree is rebuilt only when the pending set outgrows ``rebuild_minimum`` and
  ``rebuild_fraction`` of all anchors, which amortises the rebuild to O(log A) per change.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from merlin2_sailor.anchoring.anchor import Anchor, AnchorState
from merlin2_sailor.anchoring.features import extent_slack
from merlin2_sailor.errors import ConfigurationError, InvalidInputError


@dataclass(frozen=True, slots=True)
class IndexConfig:
    """``tolerance`` (m): how far an anchor may drift before it is re-indexed;
    ``rebuild_minimum`` / ``rebuild_fraction``: when the pending set triggers a rebuild."""

    tolerance: float = 0.25
    rebuild_minimum: int = 64
    rebuild_fraction: float = 0.05

    def __post_init__(self) -> None:
        if not (math.isfinite(self.tolerance) and self.tolerance >= 0.0):
            raise ConfigurationError(f"index tolerance must be >= 0 metres, got {self.tolerance}.")
        if self.rebuild_minimum < 1:
            raise ConfigurationError(f"index rebuild_minimum must be at least 1, got {self.rebuild_minimum}.")
        if not (0.0 < self.rebuild_fraction <= 1.0):
            raise ConfigurationError(f"index rebuild_fraction must be in (0, 1], got {self.rebuild_fraction}.")


class AnchorIndex:
    """Anchors by symbol, and a spatial index over their positions (see the module docstring).

    Anchors are stored in *slots*; arrays indexed by slot hold what queries and gating need
    (current and indexed positions, last-seen stamps, classes) so neither loops over Python
    objects. Whoever changes an anchor's position, last-seen stamp or class calls :meth:`refresh`.
    """

    def __init__(self, config: IndexConfig | None = None) -> None:
        self.config = config or IndexConfig()
        self.clear()

    def clear(self) -> None:
        """Drop every anchor."""
        self._slot_of: dict[str, int] = {}
        self._anchors: list[Anchor | None] = []
        self._free_slots: list[int] = []
        self._positions = np.zeros((0, 3))
        self._indexed_positions = np.zeros((0, 3))
        self._last_seen = np.zeros(0)
        self._class_names = np.zeros(0, dtype=object)
        self._search_radii = np.zeros(0)
        self._extent_slacks = np.zeros(0)
        self._alive = np.zeros(0, dtype=bool)
        self._tree: cKDTree | None = None
        self._tree_slots = np.zeros(0, dtype=np.intp)
        self._in_tree = np.zeros(0, dtype=bool)
        self._pending: set[int] = set()
        self._is_pending = np.zeros(0, dtype=bool)

    # --- container -------------------------------------------------------------------------

    def __len__(self) -> int:
        return len(self._slot_of)

    def __contains__(self, symbol: object) -> bool:
        return symbol in self._slot_of

    def __iter__(self) -> Iterator[Anchor]:
        return (self._anchors[slot] for slot in self._slot_of.values())  # type: ignore[misc]

    def get(self, symbol: str) -> Anchor | None:
        slot = self._slot_of.get(symbol)
        return None if slot is None else self._anchors[slot]

    # --- lifecycle views, derived from the anchors themselves (never kept in step by hand) ----

    def of_class(self, class_name: str) -> list[Anchor]:
        """Anchors whose voted class is ``class_name``, in symbol order."""
        slots = np.flatnonzero(self._alive & (self._class_names == class_name))
        return sorted(self.anchors_at(slots), key=_symbol)

    def on_the_forgetting_clock(self) -> list[Anchor]:
        """MISSING anchors, and tentative ones not seen where they should have been: the anchors
        the lifecycle may forget, in symbol order."""
        return sorted(
            (a for a in self if a.state is AnchorState.MISSING or a.missing_since is not None), key=_symbol
        )

    def missing(self) -> list[Anchor]:
        """MISSING anchors, in symbol order."""
        return sorted((a for a in self if a.state is AnchorState.MISSING), key=_symbol)

    def expected(self) -> list[Anchor]:
        """Anchors with an action's expectation on them, in symbol order."""
        return sorted((a for a in self if a.expectation is not None), key=_symbol)

    def visible(self) -> list[Anchor]:
        """Anchors seen in the latest processed frame."""
        return [a for a in self if a.visible]

    def anchors_at(self, slots: np.ndarray) -> list[Anchor]:
        return [self._anchors[int(slot)] for slot in slots]  # type: ignore[misc]

    def add(self, anchor: Anchor) -> None:
        if anchor.symbol in self._slot_of:
            raise InvalidInputError(f"An anchor named {anchor.symbol!r} is already indexed; symbols must be unique.")
        slot = self._free_slots.pop() if self._free_slots else self._grow()
        self._slot_of[anchor.symbol] = slot
        self._anchors[slot] = anchor
        self._alive[slot] = True
        self._in_tree[slot] = False
        self._write(slot, anchor)
        self._mark_pending(slot)
        self._rebuild_if_needed()

    def remove(self, symbol: str) -> Anchor | None:
        slot = self._slot_of.pop(symbol, None)
        if slot is None:
            return None
        anchor = self._anchors[slot]
        self._anchors[slot] = None
        self._alive[slot] = False
        self._pending.discard(slot)
        self._is_pending[slot] = False
        self._free_slots.append(slot)
        return anchor

    def refresh(self, anchor: Anchor) -> None:
        """Take in an anchor's new position, last-seen stamp and class."""
        slot = self._slot_of[anchor.symbol]
        self._write(slot, anchor)
        if self._in_tree[slot] and slot not in self._pending:
            drift = float(np.linalg.norm(self._positions[slot] - self._indexed_positions[slot]))
            if drift > self.config.tolerance:
                self._mark_pending(slot)
                self._rebuild_if_needed()

    # --- queries ----------------------------------------------------------------------------

    def oldest_last_seen(self) -> float:
        """The earliest last-seen stamp of any anchor (+inf when there are none)."""
        return float(np.min(self._last_seen[self._alive])) if self._slot_of else math.inf

    def last_seen_of(self, slots: np.ndarray) -> np.ndarray:
        return self._last_seen[slots]

    def positions_of(self, slots: np.ndarray) -> np.ndarray:
        return self._positions[slots]

    def class_names_of(self, slots: np.ndarray) -> np.ndarray:
        return self._class_names[slots]

    def search_radii_of(self, slots: np.ndarray) -> np.ndarray:
        """The search radius of each anchor's expectation (0 where it is not being searched for)."""
        return self._search_radii[slots]

    def largest_search_radius(self) -> float:
        return float(np.max(self._search_radii[self._alive], initial=0.0)) if self._slot_of else 0.0

    def extent_slacks_of(self, slots: np.ndarray) -> np.ndarray:
        """How far from each anchor's centre a partial view of it may be centred (see features.extent_slack)."""
        return self._extent_slacks[slots]

    def largest_extent_slack(self) -> float:
        return float(np.max(self._extent_slacks[self._alive], initial=0.0)) if self._slot_of else 0.0

    def within(self, points: np.ndarray, radius: float) -> list[np.ndarray]:
        """For each of the (N, 3) points, the slots of anchors within ``radius`` of it (sorted)."""
        points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        found: list[np.ndarray] = [np.zeros(0, dtype=np.intp) for _ in range(len(points))]
        if not self._slot_of or radius < 0.0 or len(points) == 0:
            return found
        pending = np.fromiter(self._pending, dtype=np.intp, count=len(self._pending))
        pending_close = (
            np.linalg.norm(points[:, np.newaxis, :] - self._positions[pending][np.newaxis, :, :], axis=2) <= radius
        )
        tree_hits = (
            self._tree.query_ball_point(points, radius + self.config.tolerance)
            if self._tree is not None
            else [[] for _ in range(len(points))]
        )
        for row, hits in enumerate(tree_hits):
            slots = self._tree_slots[np.asarray(hits, dtype=np.intp)]
            # pending slots are skipped here: the tree holds stale positions for them
            slots = slots[self._alive[slots] & ~self._is_pending[slots]]
            slots = slots[np.linalg.norm(self._positions[slots] - points[row], axis=1) <= radius]
            found[row] = np.sort(np.concatenate((slots, pending[pending_close[row]])))
        return found

    def near(self, anchor: Anchor, reach: float, horizontal: bool = False) -> list[Anchor]:
        """The other anchors whose centre lies within ``reach`` of ``anchor``'s, plus what the larger
        of the two extents explains (views of a large object are not centred alike); ``horizontal``
        measures on the floor only (a place seen from another height is the same place)."""
        own_slack = float(extent_slack(anchor.size))
        slots = self.within(anchor.position.reshape(1, 3), reach + max(own_slack, self.largest_extent_slack()))[0]
        axes = slice(0, 2) if horizontal else slice(0, 3)
        distance = np.linalg.norm(self.positions_of(slots)[:, axes] - anchor.position[axes], axis=1)
        slack = np.maximum(self.extent_slacks_of(slots), own_slack)
        return [other for other in self.anchors_at(slots[distance - slack <= reach]) if other is not anchor]

    # --- internals --------------------------------------------------------------------------

    def _write(self, slot: int, anchor: Anchor) -> None:
        position = np.asarray(anchor.position, dtype=np.float64)
        if position.shape != (3,) or not np.all(np.isfinite(position)):
            raise InvalidInputError(f"Anchor {anchor.symbol!r} has an invalid position {position.tolist()}.")
        self._positions[slot] = position
        self._last_seen[slot] = anchor.last_seen
        self._class_names[slot] = anchor.class_name
        self._search_radii[slot] = anchor.expectation.radius if anchor.expectation is not None else 0.0
        self._extent_slacks[slot] = float(extent_slack(np.asarray(anchor.size, dtype=np.float64)))

    def _grow(self) -> int:
        """Open a new slot at the end, doubling the arrays' capacity when they are full."""
        slot = len(self._anchors)
        if slot == self._positions.shape[0]:
            extra = max(16, slot)
            self._positions = np.concatenate((self._positions, np.zeros((extra, 3))))
            self._indexed_positions = np.concatenate((self._indexed_positions, np.zeros((extra, 3))))
            self._last_seen = np.concatenate((self._last_seen, np.zeros(extra)))
            self._class_names = np.concatenate((self._class_names, np.zeros(extra, dtype=object)))
            self._search_radii = np.concatenate((self._search_radii, np.zeros(extra)))
            self._extent_slacks = np.concatenate((self._extent_slacks, np.zeros(extra)))
            self._alive = np.concatenate((self._alive, np.zeros(extra, dtype=bool)))
            self._in_tree = np.concatenate((self._in_tree, np.zeros(extra, dtype=bool)))
            self._is_pending = np.concatenate((self._is_pending, np.zeros(extra, dtype=bool)))
        self._anchors.append(None)
        return slot

    def _rebuild_if_needed(self) -> None:
        limit = max(self.config.rebuild_minimum, self.config.rebuild_fraction * len(self._slot_of))
        if len(self._pending) > limit:
            self.rebuild()

    def rebuild(self) -> None:
        """Index every anchor at its current position and empty the pending set."""
        slots = np.flatnonzero(self._alive)
        self._in_tree[:] = False
        self._in_tree[slots] = True
        self._indexed_positions[slots] = self._positions[slots]
        self._tree_slots = slots
        self._tree = cKDTree(self._positions[slots]) if slots.size else None
        self._pending.clear()
        self._is_pending[:] = False

    def _mark_pending(self, slot: int) -> None:
        self._pending.add(slot)
        self._is_pending[slot] = True


def _symbol(anchor: Anchor) -> str:
    return anchor.symbol
