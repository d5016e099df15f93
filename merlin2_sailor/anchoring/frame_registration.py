"""Registering a frame's percepts on the anchors: one offset for the pose error they all share.

Why. A percept's world position is its camera-frame position carried through the robot's pose
estimate, so every percept of one frame carries the same pose error. Matching judges each
percept-anchor pair on its own, as if positions had independent errors; a shared error is then
read as every object having moved the same way. Measured in `crowded_shelf` (rules, seed 0,
3 December 2026): coming back through the doorway, the heading estimate was 1.1 degrees off and
every book on the shelf, 4 m away, was seen 0.07-0.09 m to the left of its anchor (books stand
0.18 m apart). Each percept still went to its own anchor, but fusion pulled the anchors 0.1 m
along in three frames; when the localiser corrected the pose the next frame, the percepts were
back in place, nearer the left neighbour's drifted anchor than their own, the tracker's ids had
slid one book along with the image, and two anchors took their neighbours' books for good (a new
anchor for the one left over, and the target's anchor merged away as "a second anchor in the same
space"). Every identity rule downstream then worked from anchors that had moved with the pose.

What it does. Before matching, it looks for the one horizontal offset that, added to every
percept, puts the most of them on an anchor of their class (within ``inlier_radius``) whose
colour the view does not contradict: the candidate offsets are the displacements from each
percept to each confirmed, settled anchor of its class within ``maximum_offset``, and each
candidate is scored by the number of percepts it explains, counting each anchor once. This is
the joint-compatibility idea of SLAM data association (Neira and Tardos, 2001), reduced to its
dominant term: pairings are judged together, under one pose error, rather than each on its own.

Nothing is guessed. An offset is applied only when it explains at least ``minimum_support``
percepts and either no offset explains as many (the frame sits on its anchors: each view goes to
the anchor it is nearest, and only the error they share within the inlier radius is taken out,
so that fusion does not let the anchors follow a pose error that grows a little each frame), or
it explains more than no offset does and more than twice as many as any rival offset (one
farther than twice the inlier radius from it, no offset included). A frame that could be read
two ways is not registered: that happens on a row of look-alikes when the pose error nears half
their spacing (every percept midway between two anchors: in another run of the same scenario,
half a book to the left or to the right explained six books each), or on a colourless row as
soon as the error leaves the inlier radius (one book along explains all but one). Its views of
the row are held out of matching instead (:func:`read_frame`). Colours tell such readings apart
when the row's objects differ in colour and the views are close enough to measure it. The chosen
offset is refined to the mean displacement of the percepts it explains; an object moved in a
frame on its anchors is no part of it.

What it cannot do. Only whole views count as evidence (a cut view's centre is not its object's),
and a view showing clearly less of a large landmark than its whole views did is no evidence
about that landmark (:func:`~merlin2_sailor.anchoring.partial_view.smaller_than_known`: the near
end of a couch past a thin wall is centred up to half the couch away from it, and two or three
such ends would read as a pose error); the offset is then applied to every percept of the frame.
Heading errors displace far objects more than near ones; a translation is their first-order
correction within the inlier radius.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.anchoring.anchor import Anchor, AnchorState, view_bearing, view_scale
from merlin2_sailor.anchoring.anchor_index import AnchorIndex
from merlin2_sailor.anchoring.colour_evidence import ColourEvidenceConfig, sized_view_differs
from merlin2_sailor.anchoring.expectation import ExpectationKind
from merlin2_sailor.anchoring.partial_view import smaller_than_known
from merlin2_sailor.contract.percept import Percept
from merlin2_sailor.errors import ConfigurationError


@dataclass(frozen=True, slots=True)
class RegistrationConfig:
    """``maximum_offset`` (m): the largest pose error looked for (0 turns registration off);
    ``inlier_radius`` (m): how close, horizontally, a shifted percept must come to an anchor of
    its class to be explained; ``minimum_support``: how many percepts an offset must explain;
    ``minimum_views``: how many times an anchor must have been seen to serve as a landmark."""

    maximum_offset: float = 0.3
    inlier_radius: float = 0.04
    minimum_support: int = 3
    minimum_views: int = 5

    def __post_init__(self) -> None:
        for name in ("maximum_offset", "inlier_radius"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise ConfigurationError(f"registration {name} must be a non-negative number of metres, got {value}.")
        if self.maximum_offset > 0.0 and self.inlier_radius <= 0.0:
            raise ConfigurationError("registration inlier_radius must be positive while registration is on.")
        if self.minimum_support < 2:
            raise ConfigurationError(
                f"registration minimum_support must be at least 2 (one percept is not a shared error), "
                f"got {self.minimum_support}.")
        if self.minimum_views < 1:
            raise ConfigurationError(f"registration minimum_views must be at least 1, got {self.minimum_views}.")


@dataclass(frozen=True, slots=True)
class FrameOffset:
    """The offset (m, world frame, (3,) with z 0) added to every percept of a frame; ``support``:
    the percepts it put on an anchor, against ``support_without`` with no offset."""

    offset: np.ndarray
    support: int
    support_without: int

    @property
    def off_anchors(self) -> bool:
        """Whether the frame sat off its anchors (an offset explained more than none did), rather than
        on them with a shared error within the inlier radius."""
        return self.support > self.support_without

    @property
    def distance(self) -> float:
        """How far (m) the frame's percepts were moved."""
        return float(np.linalg.norm(self.offset))


@dataclass(frozen=True, slots=True)
class FrameReading:
    """How a frame sits on the anchors: ``offset``, the shared pose error to take out (None: none
    justified); ``held``, the percepts (indices into the frame) that sit off their landmarks by a
    shared error that could be read two ways, and ``landmarks``, the symbols of the anchors they
    may be. Held percepts are kept out of matching: see :func:`read_frame`."""

    offset: FrameOffset | None = None
    held: tuple[int, ...] = ()
    landmarks: tuple[str, ...] = ()


def read_frame(
    percepts: Sequence[Percept], index: AnchorIndex, config: RegistrationConfig, whole: Sequence[bool] | None = None,
    colour: ColourEvidenceConfig | None = None,
) -> FrameReading:
    """The offset that puts the frame's percepts on the anchors, or the percepts to hold out when
    the frame is off its anchors and cannot be read one way.

    Why hold them. A frame read two ways is not registered (nothing is guessed), but matched as it
    was seen, each view on its own, it moves the anchors by the pose error it carries: a row of
    colourless books seen 0.06 m to one side for two seconds drags every anchor 0.06 m along, and
    0.13 m (more than half their spacing) puts each view on its neighbour's anchor, leaves the
    last one over as a new anchor, and the first one unseen. The crowded shelf's anchors drifted
    0.11 m that way while the robot came back through the doorway (pose errors up to 0.17 m; the
    books stand 0.18 m apart), and the scorecard took a book's anchor for its neighbour's
    (`crowded_shelf`, network, seed 2, 6 December 2026). Such a frame says that the row is there,
    not where, nor which view is which: its views of the row are held out of matching, and the
    anchors they may be are not judged unseen by it (the caller's part).

    ``whole``: per percept, whether it shows its whole object (None: all count); ``colour``: when a
    view's colour rules an anchor out (None: the defaults)."""
    if config.maximum_offset <= 0.0 or len(percepts) < config.minimum_support or len(index) == 0:
        return FrameReading()
    rows = [row for row in range(len(percepts)) if whole is None or whole[row]]
    if len(rows) < config.minimum_support:
        return FrameReading()
    positions = np.array([percepts[row].position for row in rows], dtype=np.float64)
    pair_rows, pair_columns, displacements = _candidate_pairs(
        [percepts[row] for row in rows], positions, index, config, colour or ColourEvidenceConfig())
    if len(set(pair_rows.tolist())) < config.minimum_support:
        return FrameReading()
    # (candidate offset, pair): does the pair agree with the offset? Offset 0 is candidate 0.
    candidates = np.vstack((np.zeros((1, 2)), displacements))
    agrees = np.linalg.norm(displacements[np.newaxis, :, :] - candidates[:, np.newaxis, :], axis=2) \
        <= config.inlier_radius
    support = np.array([_explained(pair_rows[row], pair_columns[row]) for row in agrees])
    best = _best_candidate(support, candidates)  # of equals, the smallest: no offset (0) first
    if support[best] < config.minimum_support:
        return FrameReading()
    rivals = np.linalg.norm(candidates - candidates[best], axis=1) > 2.0 * config.inlier_radius
    rival = int(np.flatnonzero(rivals)[np.argmax(support[rivals])]) if rivals.any() else None
    # On its anchors (no offset explains more), the frame is read as seen, each view on its
    # nearest anchor, and the error its views share within the inlier radius is taken out all the
    # same: left in, fusion let the anchors follow a pose error that grew a few centimetres a
    # frame, never far enough from them to be registered (a row of books 0.11 m along in 30
    # frames, colours or not: the anchors followed it all the way).
    if best == 0 or rival is None or support[best] > 2 * int(support[rival]):
        chosen = _one_pair_per_percept(agrees[best], pair_rows, displacements, candidates[best])
        offset = displacements[chosen].mean(axis=0)
        return FrameReading(FrameOffset(np.array([offset[0], offset[1], 0.0]), int(support[best]), int(support[0])))
    either = agrees[best] | agrees[rival]
    held = sorted({rows[int(row)] for row in pair_rows[either]})
    landmarks = sorted({anchor.symbol for anchor in index.anchors_at(np.unique(pair_columns[either]))})
    return FrameReading(held=tuple(held), landmarks=tuple(landmarks))


def shift_percepts(percepts: Sequence[Percept], frame_offset: FrameOffset | None) -> tuple[Percept, ...]:
    """The percepts with ``frame_offset`` added to their positions (as they are for None)."""
    if frame_offset is None:
        return tuple(percepts)
    return tuple(dataclasses.replace(percept, position=np.asarray(percept.position, dtype=np.float64)
                                     + frame_offset.offset) for percept in percepts)


def _is_landmark(anchor: Anchor, minimum_views: int) -> bool:
    """A settled anchor whose place the robot believes: confirmed, seen often, not carried or sought."""
    expectation = anchor.expectation
    return (anchor.state is AnchorState.CONFIRMED and anchor.times_seen >= minimum_views
            and (expectation is None or (expectation.kind is ExpectationKind.AT and not expectation.is_search)))


def _candidate_pairs(
    percepts: Sequence[Percept], positions: np.ndarray, index: AnchorIndex, config: RegistrationConfig,
    colour: ColourEvidenceConfig,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(percept row, anchor slot, horizontal displacement anchor - percept) for every percept and
    landmark of its class within ``maximum_offset`` horizontally of which it is not clearly a part
    and whose colour the view does not contradict."""
    rows: list[int] = []
    slots: list[int] = []
    displacements: list[np.ndarray] = []
    # The index searches a ball: a ground robot's pose error moves nothing up or down, so a pair
    # further apart than maximum_offset in 3D is no pair, whatever its horizontal part.
    for row, found in enumerate(index.within(positions, config.maximum_offset)):
        for slot, anchor in zip(found.tolist(), index.anchors_at(found), strict=True):
            percept = percepts[row]
            if (anchor.class_name != percept.class_name or not _is_landmark(anchor, config.minimum_views)
                    or smaller_than_known(percept, anchor)
                    or sized_view_differs(anchor.colour_by_size, percept.colour, view_scale(percept), colour,
                                          view_bearing(percept))):
                continue
            rows.append(row)
            slots.append(slot)
            displacements.append(np.asarray(anchor.position[:2], dtype=np.float64) - positions[row, :2])
    if not rows:
        return np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp), np.zeros((0, 2))
    return np.array(rows, dtype=np.intp), np.array(slots, dtype=np.intp), np.array(displacements)


def _explained(rows: np.ndarray, slots: np.ndarray) -> int:
    """How many percepts the agreeing pairs explain, each anchor explaining one percept at most."""
    return min(len(np.unique(rows)), len(np.unique(slots)))


def _best_candidate(support: np.ndarray, candidates: np.ndarray) -> int:
    """The candidate explaining the most percepts; of equals, the smallest offset."""
    ranking = np.lexsort((np.linalg.norm(candidates, axis=1), -support))
    return int(ranking[0])


def _one_pair_per_percept(
    agrees: np.ndarray, pair_rows: np.ndarray, displacements: np.ndarray, offset: np.ndarray,
) -> np.ndarray:
    """Among the pairs that agree with ``offset``, the one per percept closest to it."""
    chosen: dict[int, int] = {}
    for pair in np.flatnonzero(agrees).tolist():
        row = int(pair_rows[pair])
        error = float(np.linalg.norm(displacements[pair] - offset))
        if row not in chosen or error < float(np.linalg.norm(displacements[chosen[row]] - offset)):
            chosen[row] = pair
    return np.array(sorted(chosen.values()), dtype=np.intp)
