"""Where the camera has watched: an object that first appears at a place watched before arrived there.

Two anchors of one object (the old one MISSING, a new one confirmed elsewhere) are joined by a
search when a mission asks for the object; until then the object stands under two symbols. When
the new anchor's object cannot have been where it now stands all along, that is evidence that it
*moved* there: the camera had watched that very place, frame after frame, and saw no unknown
object of its class in it (the swap: the green mug put where the red one stood, a place the
camera had watched with only the red mug in it). An object first seen at a place never watched
before may simply have been there all along, unseen, so it is evidence of nothing: a look-alike
in an unexplored room is never taken for a lost object by this rule.

A place is a square cell of the floor plan (``cell`` metres). In each frame, the cells within
``radius`` of every percept that the camera could see (in the frustum, not hidden by nearer
depth, see :mod:`.visibility`) count one frame *watched*: the detector demonstrably worked at that
range in that direction. The cell of a percept that no known anchor explains (one acquired anew,
or reacquiring a tentative anchor), and the eight around it, also count a frame *with an unknown
object of its class*, so a
brief earlier sighting of the object itself (a tentative anchor that faded) does not make it look
like an arrival later. An anchor records, when it is acquired, how many frames its cell had been
watched without an unknown object of its class (``Anchor.watched_before``).

Not persisted: after a restart the memory starts empty, so nothing looks like an arrival until the
camera has watched again (the safe side).
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.anchoring.visibility import CameraView, VisibilityConfig, should_be_visible
from merlin2_sailor.contract.percept import Percept
from merlin2_sailor.errors import ConfigurationError

_Y_RANGE = 1 << 32
"""Cells are keyed by one integer, ``x * 2**32 + y + 2**31`` (unique while |y| < 2**31 cells)."""


def _keys(cells: np.ndarray) -> np.ndarray:
    """(N, 2) int64 cell indices -> (N,) int64 keys."""
    return cells[:, 0] * _Y_RANGE + cells[:, 1] + (_Y_RANGE >> 1)


@dataclass(frozen=True, slots=True)
class WatchConfig:
    """``cell`` (m): the side of a floor-plan cell; ``radius`` (m): how far around a percept the
    camera counts as watching; ``frames_to_arrive``: frames a place must have been watched without
    an unknown object of a class before an object of that class first seen there counts as having
    arrived (0 turns arrival evidence, and with it relocation merges, off)."""

    cell: float = 0.25
    radius: float = 0.5
    frames_to_arrive: int = 10

    def __post_init__(self) -> None:
        if not (math.isfinite(self.cell) and self.cell > 0.0):
            raise ConfigurationError(f"anchoring watch_cell must be a positive number of metres, got {self.cell}.")
        if not (math.isfinite(self.radius) and self.radius >= 0.0):
            raise ConfigurationError(f"anchoring watch_radius must be >= 0 metres, got {self.radius}.")
        if self.frames_to_arrive < 0:
            raise ConfigurationError(
                "anchoring relocation_watched_frames must be >= 0 (0 turns relocation off), "
                f"got {self.frames_to_arrive}."
            )


class WatchedPlaces:
    """Frames watched per cell, and frames with an unknown object of each class per cell."""

    def __init__(self, config: WatchConfig, visibility: VisibilityConfig) -> None:
        self.config = config
        self.visibility = visibility
        self._watched: dict[int, int] = defaultdict(int)
        self._unknown: dict[int, dict[str, int]] = defaultdict(lambda: defaultdict(int))
        reach = int(math.ceil(config.radius / config.cell)) + 1
        self._box = np.array([(dx, dy) for dx in range(-reach, reach + 1) for dy in range(-reach, reach + 1)],
                             dtype=np.int64)
        # An unknown object's own place: its cell and the eight around it (a percept's position is
        # a few centimetres off, and may fall either side of a cell's edge).
        self._own_offsets = np.array([(dx, dy) for dx in (-1, 0, 1) for dy in (-1, 0, 1)], dtype=np.int64)

    def __len__(self) -> int:
        return len(self._watched)

    def _cells(self, positions: np.ndarray) -> np.ndarray:
        """(N, 3) positions -> (N, 2) int64 cell indices."""
        plan = np.asarray(positions, dtype=np.float64).reshape(-1, 3)[:, :2]
        return np.floor(plan / self.config.cell).astype(np.int64)

    def watched_without(self, position: np.ndarray, class_name: str) -> int:
        """Frames the cell of ``position`` was watched with no unknown object of ``class_name`` in it."""
        cell = int(_keys(self._cells(position))[0])
        watched = self._watched.get(cell, 0)
        unknown = self._unknown[cell].get(class_name, 0) if cell in self._unknown else 0
        return max(watched - unknown, 0)

    def watch(self, percepts: Sequence[Percept], unknown: Sequence[bool], camera: CameraView | None) -> None:
        """Count one frame: the cells around ``percepts`` the camera could see are watched; those
        near a percept flagged ``unknown`` also had an unknown object of its class."""
        if camera is None or not percepts or self.config.frames_to_arrive == 0:
            return
        size = self.config.cell
        positions = np.array([percept.position for percept in percepts], dtype=np.float64).reshape(-1, 3)
        own = self._cells(positions)
        around = own[:, None, :] + self._box[None]  # (P, B, 2)
        offsets = (around + 0.5) * size - positions[:, None, :2]
        close = np.hypot(offsets[..., 0], offsets[..., 1]) <= self.config.radius + 0.5 * size
        heights = np.broadcast_to(positions[:, None, 2], close.shape)[close]
        cells = around[close]
        keys, first = np.unique(_keys(cells), return_index=True)
        points = np.column_stack([(cells[first] + 0.5) * size, heights[first]])
        visible = should_be_visible(points, np.full((len(keys), 3), size), camera, self.visibility)
        for key in keys[visible].tolist():
            self._watched[key] += 1
        for row in np.flatnonzero(np.asarray(unknown, dtype=bool)).tolist():
            for key in _keys(own[row] + self._own_offsets).tolist():
                self._unknown[key][percepts[row].class_name] += 1
