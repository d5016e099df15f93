"""The anchor: the link between one physical object, its percepts and its symbol.

An anchor is the anchoring layer's memory of one object: where it is (world frame), how big,
what it looks like (a small gallery of embeddings), what class the detector thinks it is, when
it was seen, and how much to trust it (:class:`AnchorState`). It satisfies the knowledge layer's
``GroundableAnchor`` / ``SizedAnchor`` protocols structurally, so grounding reads it directly.

Anchors are owned and mutated by :class:`~merlin2_sailor.anchoring.anchoring.Anchoring` only;
callers read them. Fusion rules live in :mod:`.fusion`, lifecycle rules in :mod:`.lifecycle`.
"""

from __future__ import annotations

import dataclasses
import math
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, field
from enum import Enum

import numpy as np

from merlin2_sailor.anchoring.colour_evidence import (
    ColourBySize,
    ColourEvidenceConfig,
    ColourModel,
    combined,
    combined_by_size,
    comparable_views_of,
    with_sized_view,
    with_view,
)
from merlin2_sailor.anchoring.expectation import Expectation
from merlin2_sailor.anchoring.fusion import FusionConfig, fuse_position, fuse_size, vote_class, winning_class
from merlin2_sailor.anchoring.gallery import add_view, from_bfloat16_bits, view_scales
from merlin2_sailor.contract.percept import Percept
from merlin2_sailor.knowledge.model import Provenance

#: Sightings an anchor remembers the stamps of: four seconds at 15 frames a second, more than a
#: momentary pose error's stand-in lives (:mod:`.stand_in`).
RECENT_SIGHTINGS = 64


class AnchorState(Enum):
    """How much an anchor is trusted; the values are what grounding configuration names."""

    TENTATIVE = "tentative"
    """Seen fewer times than needed to be trusted; a spurious detection stays here and fades."""
    CONFIRMED = "confirmed"
    """Seen often enough to stand for a real object."""
    MISSING = "missing"
    """Should have been seen (in view, not occluded) and was not; kept a while, in case."""
    FORGOTTEN = "forgotten"
    """Missing too long or forgotten on request; no longer anchored."""


def turned_extent(size: np.ndarray) -> np.ndarray:
    """(longer footprint side, shorter footprint side, height) of a box: its extent whichever way
    round it stands on the floor."""
    footprint = sorted((float(size[0]), float(size[1])), reverse=True)
    return np.array([footprint[0], footprint[1], float(size[2])])


def view_scale(percept: Percept) -> float:
    """The size of a view in pixels: the square root of its box's area (0 for an empty box)."""
    return math.sqrt(max(percept.box.width, 0.0) * max(percept.box.height, 0.0))


def view_bearing(percept: Percept) -> float | None:
    """The horizontal direction (radians, world frame) from the object to the camera that saw
    it, or None when the camera's position is not known (or stands right above it)."""
    if percept.viewpoint is None:
        return None
    dx = float(percept.viewpoint[0] - percept.position[0])
    dy = float(percept.viewpoint[1] - percept.position[1])
    if not (math.isfinite(dx) and math.isfinite(dy)) or math.hypot(dx, dy) < 1e-6:
        return None
    return math.atan2(dy, dx)


def seen_from(percepts: Sequence[Percept], camera_position: np.ndarray) -> tuple[Percept, ...]:
    """The percepts, each with ``camera_position`` (world frame) as its viewpoint unless it has one."""
    viewpoint = np.array(camera_position, dtype=np.float64).reshape(3)
    viewpoint.setflags(write=False)
    return tuple(percept if percept.viewpoint is not None else dataclasses.replace(percept, viewpoint=viewpoint)
                 for percept in percepts)


def _zero_vector() -> np.ndarray:
    return np.zeros(3)


@dataclass(slots=True, eq=False)
class Anchor:
    """One anchored object. Positions and sizes are (3,) float64 metres in the world frame."""

    symbol: str
    class_name: str
    position: np.ndarray
    size: np.ndarray
    first_seen: float
    last_seen: float
    state: AnchorState = AnchorState.TENTATIVE
    times_seen: int = 1
    whole_views: int = 0
    """Sightings that showed the whole object (not cut by the image's edge or an occluder)."""
    last_placed: float | None = None
    """The stamp of its latest sighting that placed it (None: as ``last_seen``, for anchors restored
    from older snapshots): a whole view, or any view before its first whole one. A part of the
    object, once it has had a whole view, keeps it alive without moving it (:meth:`absorb`), so the
    place it is at was seen then: what losing it records (:func:`.lifecycle.after_expected_but_unseen`)."""
    last_tracker_id: str = ""
    """The tracker id of the latest percept that carried one; empty when none ever did."""
    class_votes: dict[str, float] = field(default_factory=dict)
    position_variance: float = 0.01
    gallery: np.ndarray | None = None
    """(n, D) recent appearance embeddings as bfloat16 bits (:mod:`.gallery`), newest last; None
    before any was available."""
    gallery_scales: np.ndarray | None = None
    """(n,) the size in pixels (square root of the box's area) of each view in ``gallery``; NaN
    where unknown (restored from an older snapshot). See :mod:`.far_view`."""
    colour: ColourModel | None = None
    """The colours of its whole views' own pixels (:mod:`.colour_evidence`); None before any."""
    colour_by_size: ColourBySize | None = None
    """The same views' colours by the size they were seen at: what a single view is held to."""
    colour_seen: float | None = None
    """When a whole view with a colour was last fused (None: never): how long the anchor's colour
    has gone unchecked, which is what an absence is measured from (colourless views of something
    in its place say nothing about whether it is still the same object)."""
    colour_disputed: bool = False
    """A whole view of another colour stood where this anchor was expected: until a view of its own
    colour is fused, views that show no colour cannot be it either."""
    doubted_sightings: tuple[float, float] | None = None
    """Set when a view of another colour disputed it (:meth:`dispute_colour`): its sightings after
    the first stamp up to the second, all without a colour, may have been of the object that
    disputed it; None when none are in doubt. See :attr:`last_sure_sighting`."""
    unverified_sightings: tuple[float, float] | None = None
    """Set while its colour has gone unchecked (:meth:`colour_unchecked`) and views whose colour
    cannot be held to its own (:meth:`colour_untellable`: no views of about their size and side)
    reacquire it: its last sighting before the first of them, and the latest of them. Such views
    may be of another object standing in its place; until a view checks its colour they are no
    evidence that it is there (:attr:`last_sure_sighting`, :meth:`doubt_unverified`). None once a
    view of its colour is fused."""
    colour_suspected: float | None = None
    """When a first whole view of another colour stood where it was expected (None: no such view
    since its colour was last seen): a second one soon after rules the anchor out. Not kept in
    snapshots: a restart forgets a suspicion a fraction of a second old."""
    visible: bool = False
    """Reacquired or acquired in the latest processed frame."""
    missed_frames: int = 0
    """Consecutive frames in which it should have been visible and was not reacquired."""
    recovery_sightings: int = 0
    """Sightings since the anchor went missing; it is confirmed again after ``confirm_after``."""
    recovery_at: np.ndarray | None = None
    """While MISSING: where the latest of those sightings perceived it (they must stand together,
    :func:`.lifecycle.before_sighting`). Not persisted: it matters for seconds."""
    missing_since: float | None = None
    lost_after: float | None = None
    """While MISSING: its last sighting that placed it (:attr:`last_placed`) before it went missing
    (later sightings while missing, too few to bring it back, do not count; nor do parts of it that
    did not move it): an anchor born after it may be the object, moved."""
    lost_at: np.ndarray | None = None
    """While MISSING: where that sighting (``lost_after``) perceived it; a sighting while missing
    moves ``perceived_position`` but not this (:meth:`.IdentityRepair._could_have_been_carried`)."""
    recent_sightings: deque[float] = field(default_factory=lambda: deque(maxlen=RECENT_SIGHTINGS))
    """The stamps of its latest sightings, oldest first: whether it was seen while a newcomer beside
    it was (:mod:`.stand_in`). Not persisted: it matters for seconds."""
    recent_places: deque[tuple[float, float]] = field(default_factory=lambda: deque(maxlen=RECENT_SIGHTINGS))
    """Where it stood on the floor (x, y) after each of ``recent_sightings``, in step with them: whether
    it stood beside such a newcomer before the newcomer was seen, or came from elsewhere (:mod:`.stand_in`)."""
    provenance: Provenance = Provenance.PERCEIVED
    """PERCEIVED when ``position`` comes from the camera, EXPECTED when from an action's effect."""
    perceived_position: np.ndarray = field(default_factory=_zero_vector)
    """The latest position perception gave, to fall back to when an expectation is retracted."""
    expectation: Expectation | None = None
    expectation_confirmed: bool = False
    indistinguishable_from: tuple[str, ...] = ()
    """While MISSING: the symbols of anchors that a search found and could not tell from this one
    (look-alikes, each as likely to be it); empty when its identity is decided. The finder reports
    it instead of guessing, so a planner learns "not found: cannot tell which" rather than a lie."""
    found_by_look_alone: str = ""
    """An anchor a search for this one, MISSING, found that looks like it where the camera had never
    watched before it was seen (:class:`~.identity_repair.Unconfirmed`): a copy may have stood there
    all along. Taken for this one only when the search concludes, having seen no other copy
    (:meth:`~.anchoring.Anchoring.conclude_search`); cleared once taken, once a copy makes the case
    undecided, or once the candidate is gone (a sighting of this anchor on the way does not clear
    it: it may go missing again); empty: none."""
    look_pending: tuple[str, ...] = ()
    """While MISSING: anchors a search for this one met that it could not yet tell apart, for want
    of a look at some of them (:class:`~.identity_repair.LookPending`); the search looks on, and if
    it concludes with them still possible, they are what this one cannot be told from. Empty: none."""
    parts_fit: np.ndarray | None = None
    """Where its box is the box around parts of it, joined (:mod:`.parts`), not a whole view's: the
    extent (:func:`turned_extent`) of the whole one of its class its parts were fit in, slack
    included; a later view of a part beyond the box widens the box within it. Such a box holds later
    views as one seen whole would, but is never the extent its class is held to. None: not joined."""
    seen_with: set[str] = field(default_factory=set)
    """Symbols of anchors of its class seen in one frame with it: two percepts at one time are two
    objects, so these are never parts of its object (:mod:`.parts`)."""
    watched_before: int = 0
    """Frames in which the camera had watched its place, with no unknown object of its class there,
    before it was first seen (:mod:`.watched_places`): many means it arrived there since, moved."""
    left_place: np.ndarray | None = None
    """Where it stood before its latest jump (one sighting moved it far), while a newcomer seen
    there may still show that the jump went to another object (:mod:`.place_return`); None when
    it has not jumped lately. Not persisted: it matters for a few seconds."""
    left_at: float = 0.0
    """When it left ``left_place``."""

    @property
    def last_sure_sighting(self) -> float:
        """The stamp of its latest sighting that nothing since has put in doubt: what it reports as
        last seen. Views without a colour fused after its last view of its own colour, and before a
        view of another colour disputed it in its place, may have been of that other object: the red
        mug's anchor, replaced by a green mug while the robot was away, took far views of the green
        mug before a close one told the colours apart, and reported the green mug's sighting as its
        own (scenario suite, `replaced_by_another_colour`, network, 5-6 December 2026). Sightings
        taken after the first dispute count again, as they did before: the matching gave them to it
        knowing of the dispute, and an anchor still seen after one is most often its object seen
        from a new side (the green mug, swapped into the kitchen, was disputed there again and again
        while its anchor followed it; doubting every sighting up to the latest dispute had it report
        a sighting from before the swap, `swapped`, seed 0, 6 December 2026). So does a view of its
        own colour."""
        doubted = self.doubted_sightings
        sure = self.last_seen if doubted is None or self.last_seen > doubted[1] else doubted[0]
        unverified = self.unverified_sightings
        if unverified is not None and self.last_seen <= unverified[1]:
            # Its latest sightings are views its colour could not check (see unverified_sightings).
            sure = min(sure, unverified[0])
        return sure

    @property
    def place_seen(self) -> float:
        """When its place was last seen: :attr:`last_placed`, or its last sighting where that is unknown."""
        return self.last_seen if self.last_placed is None else self.last_placed

    def doubt_unverified(self, stamp: float) -> None:
        """A view at ``stamp`` whose colour cannot be held to its own reacquires it while its colour
        has gone unchecked: the view may be of another object in its place. A book of another colour,
        put where the red cookbook stood while the robot was away, was seen on the way back only at
        sizes the cookbook's anchor had no views of; the views reacquired it, confirmed the
        navigation's expectation, and approach_object, which waits for a sighting, claimed the
        cookbook in front of the robot (`removed_while_a_twin_is_unseen`, network, seed 2,
        6 December 2026). Called before the view is fused."""
        start = self.last_seen if self.unverified_sightings is None else self.unverified_sightings[0]
        self.unverified_sightings = (start, stamp)

    def dispute_colour(self) -> None:
        """A whole view of another colour stood in its place: until a view of its own colour, its
        colourless sightings since its colour was last seen are in doubt (:attr:`last_sure_sighting`).
        Only the first dispute since its colour was seen sets the doubt (:attr:`last_sure_sighting`).
        Its other records (last sighting, recent sightings) stay: they say when it was matched,
        which rules such as :mod:`.same_space` read as "stood together"; taking them back left a
        duplicate book those rules would have merged (`moved_to_another_rooms_floor`, network,
        seed 0, 6 December 2026)."""
        first = not self.colour_disputed
        self.colour_disputed = True
        if first and self.colour_seen is not None and self.colour_seen < self.last_seen:
            self.doubted_sightings = (self.colour_seen, self.last_seen)

    @property
    def confidence(self) -> float:
        """A [0, 1] summary for people and planners: grows with the percepts fused (0.63 after
        three, 0.95 after nine) and halves while the anchor is missing."""
        observed = 1.0 - math.exp(-self.times_seen / 3.0)
        return observed * (0.5 if self.state is AnchorState.MISSING else 1.0)

    @classmethod
    def from_percept(
        cls, symbol: str, percept: Percept, embedding: np.ndarray | None, config: FusionConfig, partial: bool = False
    ) -> Anchor:
        """Acquire: a new, tentative anchor initialised from one percept; from a ``partial`` view,
        so uncertain that the first whole view takes its place."""
        position = np.array(percept.position, dtype=np.float64)
        anchor = cls(
            symbol=symbol,
            class_name=percept.class_name,
            position=position,
            size=np.array(percept.size, dtype=np.float64),
            first_seen=percept.stamp,
            last_seen=percept.stamp,
            last_placed=percept.stamp,
            last_tracker_id=percept.tracker_id,
            class_votes=vote_class({}, percept.class_name, percept.score),
            position_variance=config.initial_variance * (config.partial_view_variance_factor if partial else 1.0),
            whole_views=0 if partial else 1,
            colour=None if partial else with_view(None, percept.colour),
            colour_by_size=None if partial else with_sized_view(None, percept.colour, view_scale(percept),
                                                                  view_bearing(percept)),
            colour_seen=None if partial or percept.colour is None else percept.stamp,
            visible=True,
            perceived_position=position.copy(),
        )
        anchor.note_sighting(percept.stamp)
        if embedding is not None and not partial:
            anchor.gallery, anchor.gallery_scales = add_view(None, None, embedding, view_scale(percept),
                                                             config.gallery_size)
        return anchor

    def absorb(
        self, percept: Percept, embedding: np.ndarray | None, config: FusionConfig, partial: bool = False,
        evidence: bool = True,
    ) -> None:
        """Reacquire: fuse one more percept of this object into the anchor (never overwrite).

        A ``partial`` view (cut by the image's edge or an occluder, see :mod:`.partial_view`) is
        centred on the part in view: once the anchor has had a whole view, a partial one keeps it
        alive but moves and resizes it no more; before that, it is the best there is, but weighs
        ``partial_view_variance_factor`` times less. Its crop never joins the appearance gallery.
        Such a view does not make where an action put the anchor (an expectation: the middle of a
        searched disc) a perceived position either: the bicycle, found by a search and then sought
        at the next stop, was seen there only in parts, which left it at that stop's waypoint 0.5 m
        from the bicycle, as if perceived, when the search moved on (`large_object_wheeled_away`,
        network, seed 2, 6 December 2026).

        A sighting that is no ``evidence`` of what the object looks like (a MISSING anchor's view too
        few to bring it back, :func:`.observation.reacquire`) keeps it alive, places it and sizes it,
        but its colour and look are not the object's.
        """
        self.times_seen += 1
        perceived = self.provenance is Provenance.PERCEIVED
        moves = not partial or self.whole_views == 0
        if partial and self.parts_fit is not None and perceived:
            self._widen_to(percept)
        if moves:
            self.last_placed = percept.stamp if self.last_placed is None else max(self.last_placed, percept.stamp)
            self.position, self.position_variance = fuse_position(
                self.position, self.position_variance, percept.position, percept.stamp - self.last_seen, config,
                partial,
            )
        if not partial:
            self.whole_views += 1
            self.size = fuse_size(self.size, percept.size, self.whole_views, config)
        if not partial and evidence:
            self.colour = with_view(self.colour, percept.colour)
            self.colour_by_size = with_sized_view(self.colour_by_size, percept.colour, view_scale(percept),
                                                  view_bearing(percept))
            if percept.colour is not None:
                self.colour_seen = percept.stamp
                self.colour_disputed = False
                self.colour_suspected = None
                self.doubted_sightings = None
                self.unverified_sightings = None
        self.class_votes = vote_class(self.class_votes, percept.class_name, percept.score)
        self.class_name = winning_class(self.class_votes, self.class_name)
        if embedding is not None and not partial and evidence:  # a part's look is not the object's (matching_table)
            self.gallery, self.gallery_scales = add_view(self.gallery, self.gallery_scales, embedding,
                                                         view_scale(percept), config.gallery_size)
        if percept.tracker_id:
            self.last_tracker_id = percept.tracker_id
        self.last_seen = max(self.last_seen, percept.stamp)
        self.note_sighting(percept.stamp)
        if moves or perceived:
            self.perceived_position = self.position.copy()
            self.provenance = Provenance.PERCEIVED
        self.visible = True
        self.missed_frames = 0
        self.missing_since = None

    def note_sighting(self, stamp: float) -> None:
        """Remember a sighting's stamp and where the anchor stands after it (``recent_sightings``,
        ``recent_places``)."""
        self.recent_sightings.append(stamp)
        self.recent_places.append((float(self.position[0]), float(self.position[1])))

    def _widen_to(self, percept: Percept) -> None:
        """Widen a box joined from parts to take in a view of a part beyond it, while the box around
        both still fits in a whole one (``parts_fit``): the object's extent as far as its parts show it."""
        low = np.minimum(self.position - self.size / 2.0, percept.position - percept.size / 2.0)
        high = np.maximum(self.position + self.size / 2.0, percept.position + percept.size / 2.0)
        if self.parts_fit is not None and np.all(turned_extent(high - low) <= self.parts_fit):
            self.position, self.size = (low + high) / 2.0, high - low

    def absorb_anchor(self, other: Anchor, config: FusionConfig, moved: bool = True) -> None:
        """Merge: ``other`` turned out to be this object, seen again under a new symbol.

        Its views join the gallery, and its sightings and class votes add to this one's. Where
        the object is: if it ``moved`` (found elsewhere by a search), where ``other`` saw it; if
        it reappeared where it was, ``other``'s position too, unless ``other`` saw only part of it
        and this anchor had a whole view, whose centre and size say more (as in :meth:`absorb`).
        """
        if moved or other.whole_views > 0 or self.whole_views == 0:
            self.position = other.position.copy()
            self.position_variance = other.position_variance
            self.perceived_position = other.perceived_position.copy()
            self.size = other.size.copy()
            self.whole_views = other.whole_views if moved else self.whole_views + other.whole_views
            self.parts_fit = other.parts_fit
            self.last_placed = (other.place_seen if moved else max(self.place_seen, other.place_seen))
        for class_name, votes in other.class_votes.items():
            self.class_votes[class_name] = self.class_votes.get(class_name, 0.0) + votes
        self.class_name = winning_class(self.class_votes, self.class_name)
        if other.gallery is not None:
            scales = view_scales(other.gallery, other.gallery_scales)
            for view, scale in zip(from_bfloat16_bits(other.gallery), scales, strict=True):
                self.gallery, self.gallery_scales = add_view(self.gallery, self.gallery_scales, view, float(scale),
                                                             config.gallery_size)
        self.seen_with = (self.seen_with | other.seen_with) - {self.symbol, other.symbol}
        self.colour = combined(self.colour, other.colour)
        self.colour_by_size = combined_by_size(self.colour_by_size, other.colour_by_size)
        if other.colour_seen is not None and (self.colour_seen is None or other.colour_seen > self.colour_seen):
            # Its colour was last checked by ``other``'s views, fused now: a dispute before them was
            # answered by a view of its own colour. Left as they were, the green mug's anchor, merged
            # with the anchor of the same mug moved into the kitchen, counted its colour unchecked since
            # the living room and doubted every kitchen sighting before a later dispute (`swapped`,
            # network, seed 0, 6 December 2026).
            self.colour_seen = other.colour_seen
            self.colour_disputed = other.colour_disputed
            self.colour_suspected = other.colour_suspected
            self.doubted_sightings = other.doubted_sightings
            self.unverified_sightings = other.unverified_sightings
        self.times_seen += other.times_seen
        self.last_seen = max(self.last_seen, other.last_seen)
        self.last_tracker_id = other.last_tracker_id or self.last_tracker_id
        self.visible = other.visible
        self.provenance = Provenance.PERCEIVED

    def colour_unchecked(self, stamp: float, config: ColourEvidenceConfig) -> bool:
        """Whether its colour has gone unchecked for ``config.absence`` at ``stamp`` (no whole view
        with a colour fused since), or a view of another colour disputed it: whether a view's
        colour is now a question of identity (:mod:`.colour_evidence`)."""
        checked = self.colour_seen if self.colour_seen is not None else self.last_seen
        return stamp - checked >= config.absence or self.colour_disputed

    def colour_untellable(self, percept: Percept, config: ColourEvidenceConfig) -> bool:
        """Whether the anchor knows its colour (``minimum_views`` whole views) but has too few views
        of about the percept's size, seen from about its side, to hold the percept's colour to: such
        a view's colour says nothing for or against it, as if it had none (a far view of the green
        mug standing where the red one was seen only close up must neither rule the red anchor out
        nor be fused into its colour)."""
        if config.minimum_views == 0 or self.colour is None or self.colour.views < config.minimum_views:
            return False
        near = None if self.colour_by_size is None else comparable_views_of(
            self.colour_by_size, view_scale(percept), view_bearing(percept), config)
        return near is None or near.views < config.minimum_views

    @property
    def is_active(self) -> bool:
        """Not forgotten: still anchored and matchable."""
        return self.state is not AnchorState.FORGOTTEN
