"""Identity repair: when a newer anchor is an older, lost one seen again, decided by evidence.

Matching decides identity frame by frame; two situations escape it, and both leave one object
under two symbols unless repaired:

- **a search** (top-down Find) for a MISSING anchor: the object was moved while the robot was
  elsewhere and, seen again from afar, anchored anew, because nothing then said it was the lost
  one. The search says where to look (a disc), so the newer anchor may now be recognised as it;
- **a reappearance**: a MISSING anchor's object comes back where it was lost, but another percept
  of its class (a false detection with a large box, the near end of a bicycle) took the old
  anchor in that very frame, so the real object became a newcomer.
- **a relocation**: the object was moved while the camera looked away, to a place the camera had
  watched before (:mod:`.watched_places`), so its new anchor *arrived* there; no search is
  needed when the colours agree and nothing else could be it (the green mug of a swap, put where
  the red one stood, whose old place is seen empty later).

(A fourth case, a slip's second anchor in the very space of the first, is :mod:`.same_space`'s.)

Every decision here is pure: it reads anchors and the anchor index and returns a :class:`Merge`
(``merged`` was ``kept`` all along), an :class:`Undecided` (the evidence cannot tell which of
several anchors it is), or nothing. The coordinator (:class:`~.anchoring.Anchoring`) applies them.

The evidence is the matching function itself (:func:`~.anchor_comparison.identity_scores`): the
learned matcher compares appearance; the rules compare only class, place and time. Besides a
score at or above the match threshold, a candidate must be possible at all:

- same class, nothing expected of it, trusted (confirmed, or confirmed once and missing again);
- born no earlier than the lost anchor's last sighting before it went missing: two anchors seen
  side by side at one time are two objects, whatever they look like (for an anchor *disputed* by
  a view of another colour in its place, its last sighting with its own colour: the colourless
  sightings after it may have been of the other object);
- near enough to have been carried there since (``carry_speed``): an object last seen in the
  living room is not the television the camera first sees in the bedroom a second later;
- not of another colour: the colours of the two anchors' own pixels do not rule it out
  (:mod:`.colour_evidence`; the rules have no other appearance, and the learned matcher's is
  fooled by a look-alike where the lost one stood). A mug of another colour found where the red
  mug is sought is never taken for it, with either matcher: the red mug stays missing, and a
  search reports it not found. A reappearance held apart by colour alone, by no more than one
  object's own views differ, is not decided either way: the lost anchor names the newcomer it
  cannot be told from (:meth:`IdentityRepair._in_doubt`).

A candidate is taken only when it is clearly the best (by ``ambiguity_margin``) for the lost
anchor, *and* the lost anchor is clearly the best of every other MISSING anchor the candidate
could be: two missing look-alike mugs and one mug found cannot be told apart, and then the
decision is :class:`Undecided`, naming the candidates, instead of a guess. A candidate clearly
better explained by another MISSING anchor (by the margin) is that anchor's business: nothing is
decided for the lost one, and nothing is ambiguous either. And a search's find where the camera
had never watched before it appeared is :class:`Undecided` when the robot knows a twin of the
lost object: it may be another twin that was there all along (:meth:`IdentityRepair.decide_search`);
where it knows none, the find is only recorded (:class:`Unconfirmed`) until the search, having
looked everywhere else, concludes (:meth:`IdentityRepair.conclude_search`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from merlin2_sailor.anchoring.anchor import Anchor, AnchorState
from merlin2_sailor.anchoring.anchor_comparison import SearchedDisc, identity_scores, looks_compared, score_anywhere
from merlin2_sailor.anchoring.anchor_index import AnchorIndex
from merlin2_sailor.anchoring.colour_evidence import (
    ColourEvidenceConfig,
    anchor_colour_gap,
    anchor_colours_differ,
    colours_agree,
)
from merlin2_sailor.anchoring.expectation import Expectation
from merlin2_sailor.anchoring.matcher import Matcher
from merlin2_sailor.errors import ConfigurationError


@dataclass(frozen=True, slots=True)
class RepairConfig:
    """``reappearance_distance`` (m): how close to a MISSING anchor a newcomer of its class must
    be confirmed to be considered as it reappearing (below the 0.3 m between books on a shelf;
    0 turns reappearance merges off); ``ambiguity_margin``: how much better than every rival a
    candidate must score to be taken (scores closer than this cannot tell the two apart);
    ``same_space_overlap``: the share of the smaller 3D box two anchors of a class must have in
    common to be one object (:mod:`.same_space`; 0 turns that off); ``part_slack``: the share by which
    the box around two anchors of a large object's class may exceed the largest one of the class
    seen whole for them to be parts of one object (:mod:`.parts`; 0 turns that off); ``stand_in_distance`` (m): how
    close to an anchor that was away a newcomer seen only meanwhile must stand to be it, seen off its
    place (:mod:`.stand_in`; 0 turns that off); ``place_jump`` (m): how far from a
    place an anchor must have gone, by a sudden move, for a newcomer on that place to show that the
    move went to a look-alike (:mod:`.place_return`; 0 turns that off); ``place_review`` (s): for how long after
    a jump such a newcomer is looked for; ``carry_speed`` (m/s): how fast someone may have carried
    an object away, walking with it: a newer anchor first seen farther from where a lost one was
    last perceived before it went missing than this speed covers in the time between (plus the
    reappearance distance and half of each object's size) is another object (0 turns that off)."""

    reappearance_distance: float = 0.25
    ambiguity_margin: float = 0.15
    same_space_overlap: float = 0.5
    part_slack: float = 0.25
    stand_in_distance: float = 0.25
    place_jump: float = 0.15
    place_review: float = 2.0
    carry_speed: float = 1.5

    def __post_init__(self) -> None:
        if not (math.isfinite(self.reappearance_distance) and self.reappearance_distance >= 0.0):
            raise ConfigurationError(
                "anchoring reappearance_distance must be a non-negative number of metres (0 turns the merge off), "
                f"got {self.reappearance_distance}."
            )
        if not (0.0 <= self.ambiguity_margin < 1.0):
            raise ConfigurationError(f"anchoring ambiguity_margin must be in [0, 1), got {self.ambiguity_margin}.")
        if not (math.isfinite(self.stand_in_distance) and self.stand_in_distance >= 0.0):
            raise ConfigurationError(
                "anchoring stand_in_distance must be a non-negative number of metres (0 turns it off), "
                f"got {self.stand_in_distance}."
            )
        if not (math.isfinite(self.place_jump) and self.place_jump >= 0.0):
            raise ConfigurationError(
                f"anchoring place_jump must be a non-negative number of metres (0 turns it off), got {self.place_jump}."
            )
        if not (math.isfinite(self.carry_speed) and self.carry_speed >= 0.0):
            raise ConfigurationError(f"anchoring carry_speed must be a non-negative number of metres per second "
                                     f"(0 turns it off), got {self.carry_speed}.")
        if not (math.isfinite(self.place_review) and self.place_review >= 0.0):
            raise ConfigurationError(f"anchoring place_review must be a non-negative number of seconds, "
                                     f"got {self.place_review}.")
        if not (0.0 <= self.part_slack <= 1.0):
            raise ConfigurationError(f"anchoring part_slack must be in [0, 1] (0 turns it off), got {self.part_slack}.")
        if not (0.0 <= self.same_space_overlap <= 1.0):
            raise ConfigurationError(
                f"anchoring same_space_overlap must be in [0, 1] (0 turns it off), got {self.same_space_overlap}."
            )


@dataclass(frozen=True, slots=True, eq=False)
class Merge:
    """``merged`` is ``kept`` seen again: ``kept`` keeps its symbol and takes ``merged``'s views.
    ``moved``: found elsewhere (by a search), so ``merged``'s place is where the object is now."""

    kept: Anchor
    merged: Anchor
    score: float
    reason: str
    moved: bool


@dataclass(frozen=True, slots=True, eq=False)
class Undecided:
    """The evidence cannot decide: each of the MISSING anchors ``lost`` may be any of ``found``
    (one lost mug, two look-alikes found; or two lost look-alikes, one found). ``scores`` are
    the matching function's, ``lost[0]`` against each of ``found`` then the rivals against
    ``found[0]``."""

    lost: tuple[Anchor, ...]
    found: tuple[Anchor, ...]
    scores: tuple[float, ...]
    reason: str
    also: tuple[Anchor, ...] = ()
    """Other anchors the case rests on (the twins that make a find doubtful): if one of them is
    merged or forgotten before the case is carried out, the case no longer holds."""


@dataclass(frozen=True, slots=True, eq=False)
class Unconfirmed:
    """A search found ``found``, which looks like the MISSING ``sought``, where the camera had never
    watched before it was seen, and the robot knows no twin of it: a copy may still have stood there
    all along, and the look alone cannot tell (see :meth:`IdentityRepair.decide_search`). Nothing is
    merged; the sought anchor records the candidate until the search concludes
    (:meth:`IdentityRepair.conclude_search`) or another copy turns up (then :class:`Undecided`)."""

    sought: Anchor
    found: Anchor
    score: float
    reason: str


@dataclass(frozen=True, slots=True, eq=False)
class LookPending:
    """A search met several anchors that may each be the MISSING ``sought`` and that the matching
    function scores alike, or one that it scores alike for ``sought`` and for other MISSING anchors,
    but only because it has not seen the look of some of them: their views were too partial or too
    far to compare, and their colour is not known. That is not yet a case of look-alikes, which a
    closer view may settle: nothing is merged or said, ``sought`` records them (``look_pending``)
    and the search looks on; a search that concludes with them still in question cannot tell them
    apart (:meth:`IdentityRepair.conclude_search`)."""

    sought: Anchor
    candidates: tuple[Anchor, ...]


Decision = Merge | Undecided | Unconfirmed | LookPending


class IdentityRepair:
    """Decides merges with one matcher, one match threshold, one :class:`RepairConfig` and one
    colour evidence configuration."""

    def __init__(self, matcher: Matcher, match_threshold: float, config: RepairConfig, search_tolerance: float,
                 colour: ColourEvidenceConfig | None = None, arrival_frames: int = 0,
                 far_view_ratio: float = 0.0, firm_rejection: float = 0.0) -> None:
        self.matcher = matcher
        self.colour = colour or ColourEvidenceConfig()
        self.match_threshold = match_threshold
        self.config = config
        self.search_tolerance = search_tolerance
        """Metres added to a search's radius: an object at its edge, measured with noise, is in."""
        self.arrival_frames = arrival_frames
        """Frames a place must have been watched for an object first seen there to have arrived
        (:mod:`.watched_places`); 0: relocation merges off."""
        self.far_view_ratio = far_view_ratio
        """A candidate's views under this share of the size of the lost anchor's smallest view are
        left out of its score where it has others (:mod:`.anchor_comparison`); 0: all count."""
        self.firm_rejection = firm_rejection
        """A score below it is a firm "another object" (:mod:`.far_view`'s floor); an anchor a
        search scored above it is not ruled out (:meth:`_left_in_question`)."""

    def _scores(self, candidates: Sequence[Anchor], lost: Anchor, disc: SearchedDisc) -> np.ndarray:
        return identity_scores(self.matcher, candidates, lost, disc, self.far_view_ratio)

    def _anywhere(self, candidate: Anchor, lost: Anchor) -> float:
        return score_anywhere(self.matcher, candidate, lost, self.far_view_ratio)

    # --- searches ---------------------------------------------------------------------------

    def decide_search(self, sought: Anchor, search: Expectation, index: AnchorIndex) -> Decision | None:
        """What a search for the MISSING ``sought`` within ``search``'s disc has found, if anything."""
        if sought.state is not AnchorState.MISSING or not search.is_search:
            return None
        disc = SearchedDisc(search.position, search.radius + self.search_tolerance)
        reach = disc.radius
        candidates = [
            anchor for anchor in index.of_class(sought.class_name)
            if self._possible(anchor, sought, include_missing=True)
            and float(np.linalg.norm(anchor.position[:2] - disc.centre[:2])) <= reach
        ]
        decision = self._decide(sought, candidates, index, lambda _: disc, reason="found by search", moved=True)
        return self._unless_a_twin_stood_there(decision, index) if isinstance(decision, Merge) else decision

    def _unless_a_twin_stood_there(self, merge: Merge, index: AnchorIndex) -> Decision:
        """The search's merge; :class:`Undecided` when its candidate may be another look-alike of
        the sought object that stood there all along; :class:`Unconfirmed` when only the look says
        it is the sought one.

        A search finds an anchor that looks like the lost one, in the disc; it cannot know whether
        that is the lost object, moved there, or a look-alike of it that was always there. Where the
        camera had watched the candidate's place before it appeared (:mod:`.watched_places`), it
        arrived: that is evidence it moved there. Where it had not (a room the robot never looked
        into), the look is the only evidence, and a look is shared by every twin: when the robot
        knows a twin of the lost object (another anchor whose colour agrees with the lost one's,
        both known, and that the matching function takes for it, place left out), the look is
        known not to single the lost object out. Measured: a blue book taken off a shelf, beside
        its identical twin, was reported found as the identical blue book on the bedroom's
        nightstand, first seen after the shelf's was last seen and never watched before (probe
        scenario, network, seed 0, 5 December 2026; score 0.535).

        Where the robot knows no twin, the look still does not single the lost object out: copies
        of it may stand where the robot has not looked yet. So the candidate is only recorded
        (:class:`Unconfirmed`) and the search looks on: a copy seen at a later stop is a twin, and
        the case :class:`Undecided`; with none anywhere searched, the search concludes and takes it
        (:meth:`conclude_search`). Measured: the red cookbook taken away, a red book of its make on
        the living room's shelf, never looked into, was reported found as the cookbook, while a
        third stood on the bedroom's desk (`removed_while_a_twin_is_unseen`, every seed).
        """
        if self.arrival_frames <= 0 or self._arrived(merge.merged):
            return merge
        lost, found = merge.kept, merge.merged
        recorded = index.get(lost.found_by_look_alone) if lost.found_by_look_alone else None
        if recorded is not None and recorded is not found:
            # Two finds by look alone, each taken for the lost object by the same test: which one
            # it is (if either) cannot be told. The second dog found in a room never looked into had
            # replaced the first as the candidate (`large_object_moved`, network, seed 0).
            return Undecided((lost,), (found, recorded), (merge.score,),
                             f"{found.symbol} and {recorded.symbol} both look like {lost.symbol}, each where the "
                             "camera had not watched before it was seen: either may be a copy that stood there all "
                             "along")
        twins = self._twins(lost, index, besides=found)
        if not twins:
            return Unconfirmed(lost, found, merge.score,
                               f"{found.symbol} looks like {lost.symbol}, where the camera had not watched before "
                               "it was seen: a copy may have stood there all along")
        named = [found, *(other for other in twins if other.symbol == lost.found_by_look_alone)]
        return Undecided((lost,), tuple(named), (merge.score,),
                         f"{found.symbol} looks like {lost.symbol} but so does "
                         f"{', '.join(sorted(other.symbol for other in twins))}, and the camera had not watched "
                         "where it stands before it was seen: it may be another twin that stood there all along",
                         also=tuple(twins))

    def _twins(self, lost: Anchor, index: AnchorIndex, besides: Anchor) -> list[Anchor]:
        """Other anchors (than ``lost`` and ``besides``) whose colour agrees with the lost one's, both
        known, and that the matching function takes for it, place left out."""
        return [other for other in index.of_class(lost.class_name)
                if other is not lost and other is not besides
                and other.state in (AnchorState.CONFIRMED, AnchorState.MISSING)
                and colours_agree(other.colour, lost.colour, self.colour)
                and self._anywhere(other, lost) >= self.match_threshold]

    def _also_possible(self, sought: Anchor, index: AnchorIndex, besides: Anchor) -> list[Anchor]:
        """Anchors other than ``besides`` that may as well be the MISSING ``sought``, for a search
        that has looked everywhere: possible by time, place and colour (:meth:`_possible`), taken
        for it by the matching function by everything but where they stand, and, scored where they
        stand as a search scores (:meth:`_not_firmly_rejected`), no firm rejection. Their colour
        need not be known: a stop that meets such an anchor looks on, since a later view may
        show its colour; a concluding search has no later view, and a candidate it could not rule
        out is still a candidate.

        Measured: the kitchen's dog moved to the living room, never watched, was anchored anew
        there, seen from the doorway with its colour not yet known (the network took it for the
        lost dog, place left out), and the search concluded on the bedroom's twin, found by look
        alone, as the dog (`large_object_moved`, network, seed 2, 7 December 2026)."""
        return [other for other in index.of_class(sought.class_name)
                if other is not besides and self._possible(other, sought, include_missing=True)
                and self._not_firmly_rejected(other, sought) is not None]

    def _not_firmly_rejected(self, candidate: Anchor, sought: Anchor) -> float | None:
        """The search's score of ``candidate`` where it stands (in a searched disc around it), where
        that is no firm rejection (the far-view floor) and the matching function takes it for
        ``sought`` by everything but where it stands; else None."""
        searched = float(self._scores([candidate], sought, SearchedDisc(candidate.position, self.search_tolerance))[0])
        if searched < self.firm_rejection or self._anywhere(candidate, sought) < self.match_threshold:
            return None
        return searched

    def _seen_elsewhere(self, sought: Anchor, found: Anchor) -> bool:
        """Whether ``sought`` was back (confirmed again, then lost) since ``found`` was first seen,
        away from where ``found`` stands (farther than the larger footprint of the two, plus the
        reappearance distance). A sighting too few to bring it back is no evidence: a false
        detection in a searched disc took the lost bicycle's anchor once, 1.6 m from the wheeled
        bicycle's (`large_object_wheeled_away`, network, seed 0, 6 December 2026)."""
        if sought.lost_after is None or sought.lost_at is None or sought.lost_after <= found.first_seen:
            return False
        reach = max(float(np.max(found.size[:2])), float(np.max(sought.size[:2]))) + self.config.reappearance_distance
        return float(np.linalg.norm(sought.lost_at[:2] - found.position[:2])) > reach

    def conclude_search(self, sought: Anchor, index: AnchorIndex) -> Decision | None:
        """A search that looked everywhere takes the candidate it found by look alone
        (``sought.found_by_look_alone``) for the MISSING ``sought``: a :class:`Merge`, unless a copy
        of it is anchored by now or another anchor may as well be it (:meth:`_also_possible`), then
        :class:`Undecided`, or the candidate is gone or no longer possible (None: nothing to take).
        Without a candidate, or with one its views since rule out (the matching function no longer
        takes it for the sought one, place left out), what the search met without seeing its look
        (:meth:`_still_pending`), else an :class:`Undecided` when the search left anchors in question, or an
        :class:`Unconfirmed` (a candidate to conclude on) when it left one alone and no copy
        (:meth:`_left_in_question`)."""
        if sought.state is not AnchorState.MISSING or sought.indistinguishable_from:
            return None
        found = index.get(sought.found_by_look_alone) if sought.found_by_look_alone else None
        if found is None:
            return self._still_pending(sought, index) or self._left_in_question(sought, index)
        # It was possible when found (born after the lost one's last sighting, near enough to have
        # been carried there); a sighting of the lost anchor since, where the candidate stands, must
        # not make it impossible now: a far view of the wheeled bicycle took the lost anchor for a
        # moment during the search and left it missing again, and the candidate, born before that,
        # was no longer possible (`large_object_wheeled_away`, network, seed 0, 6 December 2026).
        # A sighting elsewhere since the candidate appeared says the lost object is not it.
        if (found.class_name != sought.class_name or found.expectation is not None
                or found.state not in (AnchorState.CONFIRMED, AnchorState.MISSING)
                or anchor_colours_differ(found, sought, self.colour) or self._seen_elsewhere(sought, found)):
            return None
        score = self._anywhere(found, sought)
        if score < self.match_threshold:
            # Taken for it when found, ruled out by its views since: no longer a candidate, so the
            # search concludes as one that found none would. Measured: the living room's bicycle,
            # found by look alone while seen end-on, scored 0.13 once more of it was seen, and was
            # merged into the wheeled bicycle's symbol at the conclusion all the same
            # (`bicycle_wheeled_beside_another`, network, seed 4, 7 December 2026).
            return self._still_pending(sought, index) or self._left_in_question(sought, index)
        twins = self._twins(sought, index, besides=found)
        if twins:
            return Undecided((sought,), (found, *twins), (score,),
                             f"{found.symbol} looks like {sought.symbol} but so does "
                             f"{', '.join(sorted(other.symbol for other in twins))}: it may be another copy")
        others = self._also_possible(sought, index, besides=found)
        if others:
            return Undecided((sought,), (found, *others), (score,),
                             f"{found.symbol} looks like {sought.symbol}, but "
                             f"{', '.join(sorted(other.symbol for other in others))} may be it as well: nothing "
                             "the search saw rules them out")
        return Merge(sought, found, score, "found by search; no other copy anywhere searched", moved=True)

    def _still_pending(self, sought: Anchor, index: AnchorIndex) -> Undecided | Unconfirmed | None:
        """For a search that looked everywhere: the anchors it met without seeing their look
        (``sought.look_pending``, :class:`LookPending`) that may still be the sought one (possible,
        and taken for it by everything but where it stands). Several: :class:`Undecided`, since
        nothing seen tells them apart; one: a find by look alone (:class:`Unconfirmed`: the search
        goes to it and concludes there), as :meth:`_left_in_question` takes its one, unless another
        MISSING anchor may as well be it (:meth:`_rivals`, place left out: :class:`Undecided`);
        none: None."""
        possible = [anchor for symbol in sought.look_pending
                    if (anchor := index.get(symbol)) is not None
                    and self._possible(anchor, sought, include_missing=True)]
        taken = [(anchor, score) for anchor in possible
                 if (score := self._anywhere(anchor, sought)) >= self.match_threshold]
        pending = [anchor for anchor, _ in taken]
        scores = tuple(score for _, score in taken)
        if not pending:
            return None
        if len(pending) == 1:
            [anchor] = pending
            rivals = self._rivals(anchor, sought, index, lambda _: SearchedDisc(anchor.position, 0.0), near_only=False)
            if rivals:
                missing = (sought, *rivals)
                return Undecided(missing, (anchor,), scores,
                                 f"{anchor.symbol} may be any of {', '.join(a.symbol for a in missing)}: the search "
                                 "never saw enough of it to tell")
            return Unconfirmed(sought, anchor, scores[0],
                               f"the only anchor the search met for {sought.symbol} without seeing its look "
                               "that may still be it")
        return Undecided((sought,), tuple(pending), scores,
                         f"{sought.symbol} may be any of {', '.join(a.symbol for a in pending)}: the search never "
                         "saw enough of them to tell them apart")

    def _left_in_question(self, sought: Anchor, index: AnchorIndex) -> Undecided | Unconfirmed | None:
        """For a search that looked everywhere and found nothing: :class:`Undecided` naming the
        anchors it leaves in question, else None ("not found" is then what the evidence says). One
        anchor alone in question, with no other copy of the sought one anywhere (no twin, as
        :meth:`conclude_search` asks of a find by look alone) and the sought one not seen elsewhere
        since it appeared, is a find by look alone (:class:`Unconfirmed`): the search goes to it
        and concludes there, as with a candidate it found at a stop.

        An anchor is in question when it could have been carried where it stands since the sought
        object was lost, its colour agrees with the sought one's (both known), the matching
        function takes it for the sought object by everything but where it stands, and, scored as
        a search scores it (in a searched disc), it is no firm rejection (the far-view floor).

        Why. The learned matching function, shown a candidate in a searched disc, hedges on a look
        alone (it was trained on searched pairs whose false ones include identical twins, which no
        look tells apart, and whose true ones were seen moments apart): the hall's blue mug, moved
        to the living room while its twin stood in the kitchen, scored 0.35 in the living room's
        disc (views 0.14-0.73) and 0.95 by everything but place, and the search reported it "not
        found" though it stood in the disc (`moved_while_its_twin_is_watched`, network, seed 1,
        6 December 2026). Asked at each stop instead, the rule ended the search on a first far view
        (0.39) of the red mug moved to the bedroom, which closer views took for it (0.70):
        `moved_to_the_far_room`, seed 2. Which object it is, where several are in question or a
        copy of the sought one is anchored, the evidence cannot say; that it is absent, the
        evidence does not say either."""
        if self.firm_rejection <= 0.0:
            return None
        in_question: list[tuple[Anchor, float]] = []
        for candidate in index.of_class(sought.class_name):
            if not (self._possible(candidate, sought, include_missing=True)
                    and colours_agree(candidate.colour, sought.colour, self.colour)):
                continue
            searched = self._not_firmly_rejected(candidate, sought)
            if searched is not None:
                in_question.append((candidate, searched))
        if not in_question:
            return None
        if len(in_question) == 1:
            [(candidate, searched)] = in_question
            if not self._twins(sought, index, besides=candidate) and not self._seen_elsewhere(sought, candidate):
                # The hedge is the network's, not the evidence's: the red mug moved beside the green
                # one in a room never explored scored 0.45 in its disc (0.95 by everything but
                # place), the only red mug in the house, and the search said it could not tell
                # (`moved_beside_other_colour`, network, seed 0, 6 December 2026).
                return Unconfirmed(sought, candidate, searched,
                                   f"the only anchor the search left in question for {sought.symbol}, "
                                   "of its colour and looking like it, and no other copy of it anywhere")
        in_question.sort(key=lambda pair: (-pair[1], pair[0].symbol))
        named = ", ".join(f"{candidate.symbol} ({score:.2f})" for candidate, score in in_question)
        return Undecided((sought,), tuple(candidate for candidate, _ in in_question),
                         tuple(score for _, score in in_question),
                         f"the search found nothing it could take for {sought.symbol}, but left {named} in question: "
                         "of its colour, looking like it, and possible by time and place")

    # --- reappearances ----------------------------------------------------------------------

    def decide_reappearances(
        self, lost: Iterable[Anchor], newcomers: Iterable[Anchor], index: AnchorIndex
    ) -> list[Decision]:
        """Merges (or undecided cases) for MISSING anchors that confirmed newcomers may be.

        ``lost``: anchors that went missing this frame; ``newcomers``: anchors confirmed for the
        first time this frame. Each newcomer brings the MISSING anchors near it into question,
        so the check runs whichever of the two came last.
        """
        if self.config.reappearance_distance <= 0.0:
            return []
        near_newcomers = [anchor for newcomer in newcomers for anchor in self._near(newcomer, index)]
        decisions: list[Decision] = []
        taken: set[str] = set()
        for missing in _in_question(lost, near_newcomers):
            candidates = [
                anchor for anchor in self._near(missing, index)
                if anchor.symbol not in taken and anchor.state is AnchorState.CONFIRMED
                and self._possible(anchor, missing, include_missing=False)
            ]
            decision = self._decide(missing, candidates, index, self._where_it_went_missing,
                                    reason="reappeared where it went missing", moved=False)
            if decision is None:
                decision = self._in_doubt(missing, index, taken)
            if isinstance(decision, Merge):
                taken.add(decision.merged.symbol)
            if decision is not None:
                decisions.append(decision)
        return decisions

    def _in_doubt(self, missing: Anchor, index: AnchorIndex, taken: set[str]) -> Undecided | None:
        """Undecided where the only evidence that a newcomer in ``missing``'s very place is not it is
        a colour difference no larger than one object's own views show (at most
        ``minimum_difference_across_sides``), and the matching function takes the two for one.

        Why: colour that differs by that little is weak evidence, and deciding on it either way is a
        guess presented as fact. Measured on tours of 20 held-out generated houses
        (``scripts/colour_doubt.py``): anchors known from one glance (3 frames) were held apart
        from an anchor of a later visit of their own object in 90 of 2,208 pairs, 54 % of them by
        0.16 or less, from one of another object of the class in 8,479 of 10,633, 6.9 % of them
        (589) by 0.16 or less. Decided, such a difference made two anchors of one bird a metre from the
        wheeled bicycle: known from three frames of one glance, its views 86 s later differed by 0.11
        in one hue window, and a new anchor stood 0.02 m from the old, missing one
        (`large_object_wheeled_away`, network, seeds 0 and 1, 7 December 2026). Stated as a doubt, the
        lost anchor stays missing and names the newcomer it cannot be told from, as twins do; a
        search for it ends saying so; a larger difference (another colour put in its place) still
        decides, and a later agreement of the colours still merges them."""
        near = [
            anchor for anchor in self._near(missing, index)
            if anchor.symbol not in taken and anchor.state is AnchorState.CONFIRMED
            and self._possible_by_time_and_place(anchor, missing, include_missing=False)
        ]
        gaps = {anchor.symbol: anchor_colour_gap(anchor, missing, self.colour) for anchor in near}
        doubt_level = self.colour.minimum_difference_across_sides
        doubted = [anchor for anchor in near if 0.0 < gaps[anchor.symbol] <= doubt_level]
        if not doubted:
            return None
        scores = self._scores(doubted, missing, self._where_it_went_missing(missing))
        alike = [int(k) for k in np.argsort(-scores, kind="stable") if scores[k] >= self.match_threshold]
        if not alike:
            return None
        found = tuple(doubted[k] for k in alike)
        return Undecided((missing,), found, tuple(float(scores[k]) for k in alike),
                         f"{missing.symbol} may be {', '.join(a.symbol for a in found)}, where it went missing: "
                         f"the colours differ by {', '.join(f'{gaps[a.symbol]:.2f}' for a in found)}, no more than "
                         "one object's own views do")

    # --- relocations ------------------------------------------------------------------------

    def decide_relocations(
        self, lost: Iterable[Anchor], newcomers: Iterable[Anchor], index: AnchorIndex
    ) -> list[Merge]:
        """Merges of MISSING anchors with confirmed anchors that *arrived* elsewhere since (moved
        while the camera looked away), without a search.

        ``lost``: anchors that went missing this frame; ``newcomers``: anchors confirmed for the
        first time this frame. Stricter than a search, which knows where the mission looks: the
        newer anchor must stand where the camera had watched for ``arrival_frames`` frames with no
        unknown object of its class (:mod:`.watched_places`), so it was not there all along; both
        anchors' colours must be known and agree; no anchor near it may be what it is a duplicate
        of; and the match must be clear both ways. Where any of that fails nothing is decided (a
        search, with its own evidence, may still find the object): a case that cannot be told
        apart is left to the search rather than reported here.
        """
        if self.arrival_frames <= 0:
            return []
        of_arrivals_class = [anchor for newcomer in newcomers if self._arrived(newcomer)
                             for anchor in index.of_class(newcomer.class_name)]
        merges: list[Merge] = []
        taken: set[str] = set()
        for missing in _in_question(lost, of_arrivals_class):
            near = {anchor.symbol for anchor in self._near(missing, index)}
            candidates = [
                anchor for anchor in index.of_class(missing.class_name)
                if anchor.symbol not in taken and anchor.symbol not in near
                and self._relocation_possible(anchor, missing) and not self._may_duplicate(anchor, missing, index)
            ]
            merge = self._decide_relocation(missing, candidates, index)
            if merge is not None:
                taken.add(merge.merged.symbol)
                merges.append(merge)
        return merges

    def _decide_relocation(self, lost: Anchor, candidates: Sequence[Anchor], index: AnchorIndex) -> Merge | None:
        if not candidates:
            return None
        scores = np.array([self._anywhere(candidate, lost) for candidate in candidates])
        best = int(np.argmax(scores))
        if scores[best] < self.match_threshold:
            return None
        if any(scores[k] > scores[best] - self.config.ambiguity_margin for k in range(len(candidates)) if k != best):
            return None
        chosen = candidates[best]
        for rival in index.of_class(chosen.class_name):
            if (rival is not lost and rival.state is AnchorState.MISSING and rival.expectation is None
                    and self._relocation_possible(chosen, rival)
                    and self._anywhere(chosen, rival) > scores[best] - self.config.ambiguity_margin):
                return None
        return Merge(lost, chosen, float(scores[best]), "moved: it appeared where the camera had watched", True)

    def _arrived(self, anchor: Anchor) -> bool:
        return anchor.watched_before >= self.arrival_frames

    def _relocation_possible(self, candidate: Anchor, lost: Anchor) -> bool:
        return (
            self._arrived(candidate)
            and self._possible(candidate, lost, include_missing=False)
            and colours_agree(candidate.colour, lost.colour, self.colour)
        )

    def _may_duplicate(self, candidate: Anchor, lost: Anchor, index: AnchorIndex) -> bool:
        """Whether an older anchor near ``candidate``, not of another colour, may be its object (a
        second anchor of an object seen there all along, after a percept slid off its first)."""
        return any(
            other is not lost and other.class_name == candidate.class_name and other.first_seen < candidate.first_seen
            and not anchor_colours_differ(other, candidate, self.colour)
            for other in self._near(candidate, index)
        )

    # --- shared -----------------------------------------------------------------------------

    def _where_it_went_missing(self, lost: Anchor) -> SearchedDisc:
        """A reappearance's place: anywhere within the reappearance distance of where ``lost`` was.

        The rule bounds the place itself, so the matching function judges everything else (look,
        colour, size, time) and not the place again: a newcomer 0.19 m from where a book went
        missing, seen a tenth of a second after the book's last sighting as the localiser
        corrected the pose, was 1.3 of the book's widths away, which the learned matcher read as
        another book (0.21) although it looked the same (0.9 with the place forgiven), and the
        book kept two anchors (scenario suite, `swapped`, network, seed 1, 5 December 2026).
        """
        return SearchedDisc(np.asarray(lost.position, dtype=np.float64), self.config.reappearance_distance)

    def _decide(
        self, lost: Anchor, candidates: Sequence[Anchor], index: AnchorIndex,
        place_of: Callable[[Anchor], SearchedDisc], reason: str, moved: bool,
    ) -> Decision | None:
        """``place_of``: where each lost anchor (``lost``, its rivals) is looked for."""
        if not candidates:
            return None
        scores = self._scores(candidates, lost, place_of(lost))
        order = np.argsort(-scores, kind="stable")
        plausible = [int(k) for k in order if scores[k] >= self.match_threshold]
        if not plausible:
            return None
        best = plausible[0]
        alike = [k for k in plausible if scores[k] > scores[best] - self.config.ambiguity_margin]
        if len(alike) > 1:
            found = tuple(candidates[k] for k in alike)
            if moved and self._look_unseen(found, lost):
                return LookPending(lost, found)
            return Undecided((lost,), found, tuple(float(scores[k]) for k in alike),
                             f"{lost.symbol} may be any of {', '.join(a.symbol for a in found)}: they look alike")
        chosen = candidates[best]
        rivals = self._rivals(chosen, lost, index, place_of, near_only=not moved)
        if rivals:
            rival_scores = [float(self._scores([chosen], rival, place_of(rival))[0])
                            for rival in rivals]
            if max(rival_scores) >= scores[best] + self.config.ambiguity_margin:
                # Clearly another lost anchor's object, not this one's: nothing to decide here, and
                # nothing ambiguous (a moment's second anchor of the red mug, 0.96 for the anchor it
                # split from and 0.51 for the mug a search was looking for: test_mission_end_to_end,
                # network, 5 December 2026, where "cannot be told apart" ended the mission).
                return None
            missing = (lost, *rivals)
            if moved and any(self._look_unseen([chosen], anchor) for anchor in missing):
                # Which lost object it is, a look would tell: the search looks on (two bicycles
                # known from end-on views through doorways, one wheeled beside the other, each
                # anchor scored 1.00 by class, place and time alone: `bicycle_wheeled_beside_another`,
                # network, seed 0, 7 December 2026, said "cannot tell" at a stop before the one
                # from which the new anchor was in plain view).
                return LookPending(lost, (chosen,))
            return Undecided(missing, (chosen,), (float(scores[best]), *rival_scores),
                             f"{chosen.symbol} may be any of {', '.join(a.symbol for a in missing)}: they look alike")
        return Merge(lost, chosen, float(scores[best]), reason, moved)

    def _look_unseen(self, candidates: Sequence[Anchor], lost: Anchor) -> bool:
        """Whether the look of any of ``candidates`` is still unseen for ``lost``: the matching
        function did not compare it (:func:`~.anchor_comparison.looks_compared`) and the colours of
        the two are not both known, so nothing the robot saw of it could have ruled it out.

        Why a search defers such a case: two bicycles 0.3 m apart in a room the robot had only seen
        through doorways, each known from end-on views cut by the door frame, scored 1.00 each for
        the wheeled bicycle (the fallback's class, place and time), and the search ended at its first
        stop saying they looked alike, before the stop from which both were in plain view (probe
        scenario, a bicycle of another look beside the wheeled one, network, seed 0, 7 December
        2026). With neither appearance nor colour evidence (the rules, colours off) no view ever
        shows a look, and nothing is worth waiting for."""
        if not self.matcher.uses_appearance and self.colour.minimum_views == 0:
            return False
        compared = looks_compared(self.matcher, candidates, lost)
        return any(not seen and not colours_agree(candidate.colour, lost.colour, self.colour)
                   for candidate, seen in zip(candidates, compared, strict=True))

    def _rivals(
        self, candidate: Anchor, lost: Anchor, index: AnchorIndex, place_of: Callable[[Anchor], SearchedDisc],
        near_only: bool,
    ) -> list[Anchor]:
        """Other MISSING anchors the candidate is as likely to be as ``lost`` (judged the same way:
        from the same disc for a search, each where it went missing for a reappearance, and then
        only those near the candidate: ``near_only``)."""
        others = [
            anchor for anchor in index.of_class(candidate.class_name)
            if anchor is not lost and anchor is not candidate and anchor.state is AnchorState.MISSING
            and anchor.expectation is None and self._possible(candidate, anchor, include_missing=True)
        ]
        if near_only:
            near = {anchor.symbol for anchor in self._near(candidate, index)}
            others = [anchor for anchor in others if anchor.symbol in near]
        if not others:
            return []
        own = float(self._scores([candidate], lost, place_of(lost))[0])
        return [
            anchor for anchor in others
            if float(self._scores([candidate], anchor, place_of(anchor))[0])
            > max(own - self.config.ambiguity_margin, self.match_threshold - 1e-12)
        ]

    def _possible(self, candidate: Anchor, lost: Anchor, include_missing: bool) -> bool:
        """Whether ``candidate`` can be ``lost`` at all (before any score): see the module docstring."""
        return (self._possible_by_time_and_place(candidate, lost, include_missing)
                and not anchor_colours_differ(candidate, lost, self.colour))

    def _possible_by_time_and_place(self, candidate: Anchor, lost: Anchor, include_missing: bool) -> bool:
        """:meth:`_possible` but for colour."""
        allowed = (AnchorState.CONFIRMED, AnchorState.MISSING) if include_missing else (AnchorState.CONFIRMED,)
        last_sighting = lost.lost_after if lost.lost_after is not None else lost.last_seen
        if lost.colour_disputed and lost.colour_seen is not None:
            # A view of another colour stood in its place: its later sightings without a colour
            # (far, cut off) may have been of that other object, so only its own colour counts.
            last_sighting = min(last_sighting, lost.colour_seen)
        return (
            candidate is not lost
            and candidate.class_name == lost.class_name
            and candidate.state in allowed
            and candidate.expectation is None
            and candidate.first_seen >= last_sighting
            and self._could_have_been_carried(candidate, lost, candidate.first_seen - last_sighting)
        )

    def _could_have_been_carried(self, candidate: Anchor, lost: Anchor, gap: float) -> bool:
        """Whether ``lost``'s object could have got to where ``candidate`` stands in ``gap`` seconds.

        Born after the lost anchor's last sighting is not enough: the living room's television
        was last seen 0.73 s before the robot, in the hall, first saw the bedroom's, 5.4-5.7 m
        and two doorways away; nothing else told them apart (one make; the size, turned by 90
        degrees, is no feature the matcher trusts), so a search took the bedroom's for it, and a
        television taken out of the house was reported found (probe scenario, network, seed 0,
        5 December 2026). Nobody carries a television that fast.
        """
        if self.config.carry_speed <= 0.0:
            return True
        # Where that last sighting saw it: a sighting while missing (a false detection near the
        # hall's doorway took the television's anchor for a frame: probe, seed 8) moves the
        # perceived position but says nothing of where the object was.
        last_place = lost.lost_at if lost.lost_at is not None else lost.perceived_position
        distance = float(np.linalg.norm(np.asarray(candidate.position)[:2] - np.asarray(last_place)[:2]))
        # Each centre may be off by half its object (a part in view), and by the noise the
        # reappearance distance allows for.
        off_centre = (float(np.max(candidate.size[:2])) + float(np.max(lost.size[:2]))) / 2.0
        return distance <= self.config.carry_speed * gap + self.config.reappearance_distance + off_centre

    def _near(self, anchor: Anchor, index: AnchorIndex) -> list[Anchor]:
        """Other anchors within the reappearance distance of this one (see :meth:`AnchorIndex.near`)."""
        return index.near(anchor, self.config.reappearance_distance)


def _in_question(lost: Iterable[Anchor], brought_in: Iterable[Anchor]) -> list[Anchor]:
    """The MISSING anchors with nothing expected of them among those that went missing this frame
    and those a newcomer brings into question, each once, in symbol order."""
    in_question = {anchor.symbol: anchor for anchor in (*lost, *brought_in)}
    return [
        in_question[symbol] for symbol in sorted(in_question)
        if in_question[symbol].state is AnchorState.MISSING and in_question[symbol].expectation is None
    ]
