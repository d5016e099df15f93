"""Anchor against anchor, scored by the matching function itself: the evidence behind a merge.

Identity repair asks "is this newer anchor the older, lost one, seen again?". That is the question
the matching function M answers for a percept and an anchor, so it is answered by the very same
matcher (the learned one compares appearance; the rules only class, place and time): the newer
anchor plays the percept, as it was when it first appeared (its first sighting's stamp, so the
time feature measures the gap since the lost anchor was last seen), once per view in its
appearance gallery, each view against the lost anchor's nearest gallery view (as in matching), and
the candidate's score is the mean over its views. Not the best view: the matching function is
calibrated for one view, and the best of ten views of a green mug scored 0.74 against the lost
blue mug where their median was 0.24; one lucky view is not evidence that the whole anchor is
the lost object.

The lost anchor's last sighting is the one before it went missing (``lost_after``), not a
sighting while missing, too few to bring it back, which may have been of the very candidate: in
`twin_moved` (network, seed 3, 4 December) the search never took the moved mug's new anchor for
it; at the end of the run the sought anchor's latest sighting, while missing, was 148 s after the
candidate's first, which makes the time between them negative and the network's score 0.46, under
the threshold; from its last sighting before it went missing, 0.57.

For a search, where the lost object is sought is a disc rather than a point: the lost anchor is
measured from that disc (anywhere in it counts as in place), as the matching table measures a
searched anchor; every other feature is unchanged.

The mean leaves out the candidate's views too far to tell from the lost anchor's (under
``far_view_ratio`` of the size of the lost anchor's smallest view: the criterion and the
measurement of :mod:`.far_view`), unless the candidate has no other. A gallery keeps views of
several sizes (:func:`.gallery.add_view`), so a candidate first seen from across a room keeps
those far views after the robot comes close; each is a blurred copy of what the lost anchor's
gallery saw sharp, and the network scores it low whatever the object. In the real-MERLIN2 mission
test (CI, 5 December) the red mug carried to the bedroom was never taken for its lost anchor: its
new anchor's one close view scored 0.75 in the searched disc and its three views of 10-18 px,
against the lost anchor's 48-61 px, 0.30-0.53; the mean, 0.48, was under the threshold.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.anchoring.anchor import Anchor
from merlin2_sailor.anchoring.far_view import smallest_view
from merlin2_sailor.anchoring.features import AnchorColumns, PerceptColumns, pair_features
from merlin2_sailor.anchoring.gallery import from_bfloat16_bits, view_scales
from merlin2_sailor.anchoring.matcher import Matcher
from merlin2_sailor.anchoring.partial_view import comparable_views


@dataclass(frozen=True, slots=True)
class SearchedDisc:
    """Where a lost object is being looked for: anywhere within ``radius`` metres of ``centre``."""

    centre: np.ndarray
    radius: float


def identity_scores(
    matcher: Matcher, candidates: Sequence[Anchor], lost: Anchor, disc: SearchedDisc | None = None,
    far_view_ratio: float = 0.0,
) -> np.ndarray:
    """M(candidate as first perceived, lost), averaged over the candidate's views comparable in size
    with the lost anchor's (all of them when ``far_view_ratio`` is 0 or none is), for each
    candidate: a (len(candidates),) array in [0, 1]."""
    if not candidates:
        return np.zeros(0)
    percepts, owners, scales = _candidates_as_percepts(candidates, matcher.uses_appearance
                                                       & _comparable(candidates, lost))
    anchors = AnchorColumns.from_anchors([lost])
    if lost.lost_after is not None:
        # Its last sighting is the one before it went missing, as for who may be it at all
        # (identity_repair._possible): a sighting while missing, too few to bring it back, may
        # have been of the very candidate, which would then seem seen before it was lost.
        anchors = dataclasses.replace(anchors, last_seen=np.array([lost.lost_after], dtype=np.float64))
    if disc is None:
        anchors = dataclasses.replace(anchors, perceived_positions=None, search_radii=None)
    else:
        anchors = dataclasses.replace(
            anchors,
            positions=np.asarray(disc.centre, dtype=np.float64).reshape(1, 3),
            perceived_positions=None,
            search_radii=np.array([float(disc.radius)]),
        )
    rows = np.arange(len(owners))
    features = pair_features(
        percepts, anchors, rows, np.zeros(len(owners), dtype=np.intp), matcher.feature_config,
        with_appearance=matcher.uses_appearance,
    )
    per_view = matcher.score_pairs(features)
    counted = _views_counted(candidates, owners, scales, smallest_view(lost) * far_view_ratio)
    views = np.bincount(owners, weights=counted, minlength=len(candidates))
    return np.bincount(owners, weights=per_view * counted, minlength=len(candidates)) / views


def looks_compared(matcher: Matcher, candidates: Sequence[Anchor], lost: Anchor) -> np.ndarray:
    """(len(candidates),) True where :func:`identity_scores` reads the candidate's look against the
    lost anchor's: the matcher compares appearance, the two are comparable views of one extent (see
    there) and both have appearance views. Where it is False the score is the fallback's: class,
    place and time only, as the rules see any pair."""
    if not candidates or not matcher.uses_appearance or lost.gallery is None or not len(lost.gallery):
        return np.zeros(len(candidates), dtype=bool)
    has_views = np.array([anchor.gallery is not None and len(anchor.gallery) > 0 for anchor in candidates])
    return _comparable(candidates, lost) & has_views


def _comparable(candidates: Sequence[Anchor], lost: Anchor) -> np.ndarray:
    """(len(candidates),) whether each candidate's views and the lost anchor's show one extent."""
    # A candidate that knows only a part of a large lost object (a view end-on, through a door)
    # is compared without its look, as a partial percept is (matching_table.comparable_views);
    # so is a lost anchor that knew only a part of what the candidate shows whole (a bicycle's
    # end anchored first, the whole bicycle later: scenario suite, 4 December, a duplicate).
    # So is a candidate whose box was joined from parts (:mod:`.parts`): its views are its parts',
    # the whole object's look it never saw (the joined bicycle of `large_object_wheeled_away` was
    # never taken by the search for the bicycle it was: scenario suite, network, 6 December 2026).
    sizes = np.array([anchor.size for anchor in candidates])
    return (comparable_views(sizes, None, [lost])[:, 0]
            & comparable_views(np.asarray(lost.size).reshape(1, 3), None, candidates)[0]
            & np.array([anchor.parts_fit is None for anchor in candidates]))


def score_anywhere(matcher: Matcher, candidate: Anchor, lost: Anchor, far_view_ratio: float = 0.0) -> float:
    """M(candidate, lost) with place left out (measured from a disc of radius 0 at the candidate):
    whether it is the lost object by everything but where it stands."""
    return float(identity_scores(matcher, [candidate], lost, SearchedDisc(candidate.position, 0.0),
                                 far_view_ratio)[0])


def _views_counted(
    candidates: Sequence[Anchor], owners: np.ndarray, scales: np.ndarray, far_below: float
) -> np.ndarray:
    """(rows,) 1.0 for each pseudo-percept row counted in its candidate's mean, else 0.0: rows whose
    view is ``far_below`` pixels or larger (or of unknown size), or every row of a candidate that
    has no such view."""
    counted = ~(scales < far_below)  # NaN (an unknown size) compares False: counted
    has_near_view = np.bincount(owners, weights=counted, minlength=len(candidates)) > 0
    return (counted | ~has_near_view[owners]).astype(np.float64)


def _candidates_as_percepts(
    candidates: Sequence[Anchor], with_views: np.ndarray
) -> tuple[PerceptColumns, np.ndarray, np.ndarray]:
    """One pseudo-percept per gallery view of each candidate (one, without embedding, if it has
    none or ``with_views`` is False for it); returns the columns and, per row, the candidate it
    stands for and the size of its view (NaN: unknown, or no view)."""
    owners: list[int] = []
    views: list[np.ndarray | None] = []
    sizes: list[float] = []
    for number, anchor in enumerate(candidates):
        usable = with_views[number] and anchor.gallery is not None and len(anchor.gallery)
        gallery = anchor.gallery if usable else None
        entries = [None] if gallery is None else list(from_bfloat16_bits(gallery))
        owners.extend([number] * len(entries))
        views.extend(entries)
        sizes.extend([math.nan] if gallery is None else view_scales(gallery, anchor.gallery_scales).tolist())
    owner_array = np.asarray(owners, dtype=np.intp)
    chosen = [candidates[owner] for owner in owners]
    known = np.array([view is not None for view in views], dtype=bool)
    embeddings = None
    if known.any():
        dimension = next(view for view in views if view is not None).shape[-1]
        embeddings = np.zeros((len(views), dimension), dtype=np.float32)
        for row, view in enumerate(views):
            if view is not None:
                embeddings[row] = view
    columns = PerceptColumns(
        class_names=np.array([a.class_name for a in chosen], dtype=object),
        positions=np.array([a.position for a in chosen], dtype=np.float64).reshape(-1, 3),
        sizes=np.array([a.size for a in chosen], dtype=np.float64).reshape(-1, 3),
        stamps=np.array([a.first_seen for a in chosen], dtype=np.float64),
        tracker_ids=np.array([""] * len(chosen), dtype=object),
        embeddings=embeddings,
        has_embedding=known,
    )
    return columns, owner_array, np.asarray(sizes, dtype=np.float64)
