"""Two anchors of one class in one space are one object: the second is what a slip left behind.

When percepts slide (the pose estimate drifts while the robot drives, seven books stand 2 cm
apart), the assignment can hand one object's percepts to its neighbour's anchor for a few frames
and give the object a second anchor; once the percepts are back in place, one of the two is seen
there and the other goes MISSING on the very spot. Identity repair's other rules leave such a
pair alone, since both were seen at one time ("two anchors seen side by side are two objects").
But two objects cannot fill the same space: when the 3D boxes of a MISSING anchor and of an
anchor of its class confirmed and seen in this frame share at least ``minimum_overlap`` of the
smaller box, each one's centre lies within the other's footprint, and their colours do not
differ, they are one object. Measured on the scenario suite of 3 December 2026: every duplicate
anchor left in `crowded_shelf` (both matchers) and three of the five in `removed` (rules) were
such pairs (overlap 0.6-1.0).

The centres, not only the overlap: a small box wholly inside a large one shares all of the
smaller's volume without the two being one space. In five seeds of `bicycle_wheeled_beside_another`
(network, 7 December 2026) the wheeled bicycle's anchor, on its near end, was twice forgotten into
the anchor of the bicycle it stood 0.65 m beside (overlap 0.74 and 0.79, centres 0.67-0.7 m apart
across the bicycles' 0.35 m width): that anchor's box must have been about a metre wide, one
drawn across both bicycles seen end-on (the log then kept no boxes; merges now report both).

No merge without evidence: with a matcher that reads appearance, the matching function must also
take the younger anchor, its place left out (both stand on one spot by construction), for the
older one (:func:`~.anchor_comparison.score_anywhere`, as the other repairs ask). Overlap and
colour alone let a red book whose anchor slid onto its blue neighbour's missing one be merged
into it (`crowded_shelf`, network, seed 0, 3 December: overlap 0.68, neither colour known from
3-4 m, and the mission's target symbol merged away). The rules read no appearance and are judged
as before.

The older symbol stays, as in every merge, since it is the one the planner knows: a MISSING
anchor older than the one seen takes it over (a :class:`~.identity_repair.Merge`); a younger
MISSING one is forgotten as a :class:`Duplicate` (its few sightings were the slip's). A pair that
never stood together (the seen one born after the missing one's last sighting) is not a slip but
perhaps an object put in another's place, which the reappearance rules judge instead.

Nor can one object's space hold two: a MISSING anchor inside whose box two anchors of its class
seen this frame each lie (at least ``minimum_overlap`` of each inside it, each smaller than it),
two that were seen at one time and so are two objects, was anchored from a box drawn across both
(a detector's box around two books of a shelf, its depth the books' own), not from an object of
its own. It is forgotten as a :class:`Duplicate` of the one most inside it. Neither colour nor
look is asked: a box across two objects blends both, so it is like neither. Measured in the
scenario suite (`twin_removed_from_the_shelf`, network, seed 2, 6 December 2026): a book anchor
born of such a box stood MISSING between two shelf books for the rest of the mission (its colour
differed from each, so the pairwise rule above left it), a duplicate of the scorecard. A part's
anchor is never two objects' (:mod:`.parts`: parts are never seen at one time), so a whole object
seen only in parts is left alone.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.anchoring.anchor import Anchor, AnchorState
from merlin2_sailor.anchoring.anchor_comparison import score_anywhere
from merlin2_sailor.anchoring.anchor_index import AnchorIndex
from merlin2_sailor.anchoring.colour_evidence import ColourEvidenceConfig, anchor_colours_differ
from merlin2_sailor.anchoring.identity_repair import Merge
from merlin2_sailor.anchoring.matcher import Matcher


@dataclass(frozen=True, slots=True, eq=False)
class Duplicate:
    """``duplicate`` (MISSING) was a second anchor of ``kept``'s object: it is forgotten.
    ``overlap``: the share of the smaller 3D box the two have in common (0 where the evidence is
    time rather than space, :mod:`.stand_in`); ``score``: the matching function's, where asked."""

    kept: Anchor
    duplicate: Anchor
    overlap: float
    reason: str
    score: float | None = None
    what: str = "a second anchor of its object"
    """What the duplicate was, for the FORGOTTEN event."""

    @property
    def explanation(self) -> str:
        """What the FORGOTTEN event says of it."""
        return f"{self.reason}: {self.what}"


def shared_volume(first: Anchor, second: Anchor) -> float:
    """The share of the smaller of the two anchors' axis-aligned boxes that lies in both (0..1)."""
    low = np.maximum(first.position - first.size / 2.0, second.position - second.size / 2.0)
    high = np.minimum(first.position + first.size / 2.0, second.position + second.size / 2.0)
    common = float(np.prod(np.clip(high - low, 0.0, None)))
    smaller = min(float(np.prod(first.size)), float(np.prod(second.size)))
    return common / smaller if smaller > 0.0 else 0.0


def centred_on_each_other(first: Anchor, second: Anchor) -> bool:
    """Whether each anchor's centre lies within the other's footprint on the floor."""
    offset = np.abs(first.position[:2] - second.position[:2])
    return bool(np.all(offset <= np.minimum(first.size[:2], second.size[:2]) / 2.0))


def decide_same_space(
    seen: Iterable[Anchor], index: AnchorIndex, minimum_overlap: float, colour: ColourEvidenceConfig,
    matcher: Matcher | None = None, match_threshold: float = 0.5,
) -> list[Merge | Duplicate]:
    """Decisions for MISSING anchors that share their space with an anchor ``seen`` this frame
    (0 ``minimum_overlap`` turns the rule off); ``matcher``: when it reads appearance, it must
    take the younger of each pair for the older at ``match_threshold`` or more."""
    if minimum_overlap <= 0.0:
        return []
    current = {anchor.symbol: anchor for anchor in seen
               if anchor.state is AnchorState.CONFIRMED and anchor.visible and anchor.expectation is None}
    if not current:
        return []
    anchors = list(current.values())
    radius = max(float(np.linalg.norm(anchor.size)) for anchor in anchors) + index.largest_extent_slack()
    decisions: list[Merge | Duplicate] = []
    settled: set[str] = set()
    for anchor, slots in zip(anchors, index.within(np.array([a.position for a in anchors]), radius), strict=True):
        for other in index.anchors_at(slots):
            if anchor.symbol in settled or other.symbol in settled or not _may_be_one(anchor, other, colour):
                continue
            overlap = shared_volume(anchor, other)
            if (overlap < minimum_overlap or not centred_on_each_other(anchor, other)
                    or not _looks_alike(anchor, other, matcher, match_threshold)):
                continue
            settled.update((anchor.symbol, other.symbol))
            if other.first_seen < anchor.first_seen:
                decisions.append(Merge(other, anchor, overlap, "a second anchor in the same space", moved=True))
            else:
                decisions.append(Duplicate(anchor, other, overlap, f"in the same space as {anchor.symbol}"))
    decisions.extend(_boxes_across(anchors, index, radius, minimum_overlap, settled))
    return decisions


def _boxes_across(
    seen: list[Anchor], index: AnchorIndex, radius: float, minimum_overlap: float, settled: set[str]
) -> list[Duplicate]:
    """MISSING anchors whose space two of the ``seen`` anchors, two objects, fill (module docstring)."""
    inside: dict[str, list[tuple[float, Anchor]]] = {}
    missing: dict[str, Anchor] = {}
    for anchor, slots in zip(seen, index.within(np.array([a.position for a in seen]), radius), strict=True):
        for other in index.anchors_at(slots):
            if other.symbol in settled or anchor.symbol in settled or not _stood_with(anchor, other):
                continue
            if float(np.prod(anchor.size)) >= float(np.prod(other.size)):
                continue
            overlap = shared_volume(anchor, other)
            if overlap >= minimum_overlap:
                inside.setdefault(other.symbol, []).append((overlap, anchor))
                missing[other.symbol] = other
    duplicates = []
    for symbol, held in inside.items():
        held.sort(key=lambda pair: -pair[0])
        pairs = [(first, second) for i, (_, first) in enumerate(held) for _, second in held[i + 1:]
                 if second.symbol in first.seen_with or first.symbol in second.seen_with]
        if not pairs:
            continue
        first, second = pairs[0]
        overlap = next(share for share, anchor in held if anchor is first)
        duplicates.append(Duplicate(first, missing[symbol], overlap,
                                    f"a box across {first.symbol} and {second.symbol}, which fill its space",
                                    what="not an object of its own"))
        settled.add(symbol)
    return duplicates


def _may_be_one(seen: Anchor, missing: Anchor, colour: ColourEvidenceConfig) -> bool:
    """A MISSING anchor of the seen one's class, with nothing expected of it, that stood together
    with it at some time, and not of another colour."""
    return _stood_with(seen, missing) and not anchor_colours_differ(seen, missing, colour)


def _stood_with(seen: Anchor, missing: Anchor) -> bool:
    """A MISSING anchor of the seen one's class, with nothing expected of it, that stood together
    with it at some time."""
    return (
        missing is not seen
        and missing.state is AnchorState.MISSING
        and missing.expectation is None
        and missing.class_name == seen.class_name
        and seen.first_seen < missing.last_seen
    )


def _looks_alike(first: Anchor, second: Anchor, matcher: Matcher | None, threshold: float) -> bool:
    """Whether an appearance matcher takes the younger anchor for the older, place left out
    (True for a matcher without appearance: it has no evidence to add)."""
    if matcher is None or not matcher.uses_appearance:
        return True
    younger, older = (first, second) if first.first_seen >= second.first_seen else (second, first)
    return score_anywhere(matcher, younger, older) >= threshold
