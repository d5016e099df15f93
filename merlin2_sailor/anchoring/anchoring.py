"""The anchoring process: acquire, reacquire, track and find, with the anchor lifecycle.

One frame (:meth:`Anchoring.process`) follows the paper's algorithm, then the lifecycle:

1. anchors missing for too long are forgotten;
2. with no anchors, every percept is acquired; otherwise the matching table (gated, batched) is
   built and assigned: a pair at or above ``match_threshold`` reacquires (the anchor fuses the
   percept), every other percept acquires a new anchor with a fresh symbol;
3. an anchor not reacquired is checked against the camera: only if it should have been visible
   (in the frustum, not occluded by nearer depth) does it count towards MISSING; an anchor with
   an expected location seen empty has that expectation RETRACTED instead;
4. a newcomer confirmed where a MISSING anchor of its class was lost is that object reappearing,
   and is merged into it (see :meth:`Anchoring._merge_reappearances`).

:meth:`Anchoring.track` moves anchors without observation (static objects stay put; carried ones
follow the robot) and applies time-outs; :meth:`Anchoring.expect` records an action's expected
effect; :meth:`Anchoring.find` answers top-down queries; :meth:`Anchoring.snapshot` /
:meth:`Anchoring.restore` carry anchors across restarts.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from merlin2_sailor.anchoring.anchor import Anchor, AnchorState
from merlin2_sailor.anchoring.anchor_index import AnchorIndex, IndexConfig
from merlin2_sailor.anchoring.assignment import assign
from merlin2_sailor.anchoring.events import AnchorEvent, AnchorEventKind
from merlin2_sailor.anchoring.expectation import Expectation, ExpectationKind
from merlin2_sailor.anchoring.features import extent_slack
from merlin2_sailor.anchoring.fusion import FusionConfig
from merlin2_sailor.anchoring.gallery import gallery_similarity
from merlin2_sailor.anchoring.lifecycle import LifecycleConfig, after_expected_but_unseen, after_sighting, expire
from merlin2_sailor.anchoring.matcher import Matcher
from merlin2_sailor.anchoring.matching_table import Embedder, MatchingTableBuilder, MatchingTableConfig, with_embeddings
from merlin2_sailor.anchoring.partial_view import PartialViewConfig, partial_views, smaller_than_known
from merlin2_sailor.anchoring.rule_matcher import RuleMatcher
from merlin2_sailor.anchoring.snapshot import SNAPSHOT_FORMAT, SNAPSHOT_VERSION, anchor_from_dict, anchor_to_dict
from merlin2_sailor.anchoring.symbols import SymbolCounter, SymbolFactory
from merlin2_sailor.anchoring.visibility import CameraView, VisibilityConfig, should_be_visible
from merlin2_sailor.contract.percept import Percept
from merlin2_sailor.contract.pose import Pose
from merlin2_sailor.errors import ConfigurationError, InvalidInputError, KnowledgeError, SailorError
from merlin2_sailor.knowledge.model import Provenance
from merlin2_sailor.knowledge.naming import to_identifier

#: find() prefers anchors in this order of state.
_FIND_STATE_RANK = {AnchorState.CONFIRMED: 0, AnchorState.TENTATIVE: 1, AnchorState.MISSING: 2}


@dataclass(frozen=True, slots=True)
class AnchoringConfig:
    """Everything the anchoring core can be tuned with; every part validates itself.

    ``match_threshold``: the score a pair needs to reacquire (the paper's 0.5);
    ``world_frame``: the fixed frame percepts must be expressed in;
    ``expectation_tolerance`` (m): how close to an expected place a reacquired object must be
    to confirm the expectation (farther retracts it);
    ``merge_similarity``: the cosine similarity of appearance galleries below which a search
    never takes an anchor born while the sought one was missing as the sought one, and a
    newcomer is never taken for a missing anchor reappearing;
    ``reappearance_distance`` (m): how close to a MISSING anchor a newcomer of its class must be
    confirmed to be taken for it (below the 0.3 m between books on a shelf).
    """

    match_threshold: float = 0.5
    world_frame: str = "map"
    expectation_tolerance: float = 1.0
    merge_similarity: float = 0.8
    reappearance_distance: float = 0.25
    table: MatchingTableConfig = field(default_factory=MatchingTableConfig)
    fusion: FusionConfig = field(default_factory=FusionConfig)
    partial_view: PartialViewConfig = field(default_factory=PartialViewConfig)
    lifecycle: LifecycleConfig = field(default_factory=LifecycleConfig)
    visibility: VisibilityConfig = field(default_factory=VisibilityConfig)
    index: IndexConfig = field(default_factory=IndexConfig)

    def __post_init__(self) -> None:
        if not (0.0 < self.match_threshold <= 1.0):
            raise ConfigurationError(f"anchoring match_threshold must be in (0, 1], got {self.match_threshold}.")
        if not self.world_frame:
            raise ConfigurationError("anchoring world_frame must name the fixed frame (e.g. map or odom).")
        if not (math.isfinite(self.expectation_tolerance) and self.expectation_tolerance > 0.0):
            raise ConfigurationError(
                "anchoring expectation_tolerance must be a positive number of metres, "
                f"got {self.expectation_tolerance}."
            )
        if not (math.isfinite(self.reappearance_distance) and self.reappearance_distance >= 0.0):
            raise ConfigurationError(
                "anchoring reappearance_distance must be a non-negative number of metres (0 turns the merge off), "
                f"got {self.reappearance_distance}."
            )


@dataclass(frozen=True, slots=True, eq=False)
class AnchoringResult:
    """What one call changed. ``percept_symbols[i]`` is the symbol percept i was anchored to."""

    stamp: float
    acquired: tuple[Anchor, ...] = ()
    reacquired: tuple[Anchor, ...] = ()
    missing: tuple[Anchor, ...] = ()
    forgotten: tuple[Anchor, ...] = ()
    events: tuple[AnchorEvent, ...] = ()
    percept_symbols: tuple[str, ...] = ()


@dataclass(slots=True)
class _Changes:
    """Collects one call's changes in order, then freezes them into an :class:`AnchoringResult`."""

    stamp: float
    acquired: list[Anchor] = field(default_factory=list)
    reacquired: list[Anchor] = field(default_factory=list)
    missing: list[Anchor] = field(default_factory=list)
    forgotten: list[Anchor] = field(default_factory=list)
    events: list[AnchorEvent] = field(default_factory=list)
    confirmed_newcomers: list[Anchor] = field(default_factory=list)
    """Anchors confirmed for the first time in this call: not part of the result."""

    def event(self, kind: AnchorEventKind, symbol: str, **details: Any) -> None:
        self.events.append(AnchorEvent(kind, symbol, self.stamp, details))

    def result(self, percept_symbols: Sequence[str] = ()) -> AnchoringResult:
        return AnchoringResult(
            self.stamp,
            tuple(self.acquired),
            tuple(self.reacquired),
            tuple(self.missing),
            tuple(self.forgotten),
            tuple(self.events),
            tuple(percept_symbols),
        )


class Anchoring:
    """The ROS-free anchoring core; a node feeds it percepts and camera views and publishes results.

    ``matcher`` defaults to the :class:`~.rule_matcher.RuleMatcher` (a trained
    :class:`~.matching_network.NetworkMatcher` plugs in the same way); ``embedder`` embeds crops
    when the matcher uses appearance; ``symbol_factory`` names new anchors, normally
    ``KnowledgeBase.new_symbol`` so that symbols are never reused, even across restarts.

    Typical node loop::

        anchoring = Anchoring(config, matcher, embedder, knowledge_base.new_symbol)
        result = anchoring.process(percepts, CameraView(intrinsics, camera_to_world, depth), stamp)
        publish(result.events)            # and ground result.acquired / reacquired / forgotten
        anchoring.track(now, robot_pose)  # on a timer: carried objects, time-outs

    Not thread-safe: call it from one thread (one callback group in a node).
    """

    def __init__(
        self,
        config: AnchoringConfig | None = None,
        matcher: Matcher | None = None,
        embedder: Embedder | None = None,
        symbol_factory: SymbolFactory | None = None,
    ) -> None:
        self.config = config or AnchoringConfig()
        self.matcher = matcher or RuleMatcher()
        self.embedder = embedder
        counter = SymbolCounter()
        self._own_counter: SymbolCounter | None = counter if symbol_factory is None else None
        self._new_symbol: SymbolFactory = symbol_factory or counter
        self._table_builder = MatchingTableBuilder(self.matcher, self.config.table, embedder)
        self._index = AnchorIndex(self.config.index)
        self._by_class: dict[str, set[str]] = {}
        self._missing: set[str] = set()
        self._expected: set[str] = set()
        self._visible: set[str] = set()
        self._latest_stamp = -math.inf

    # --- reading ----------------------------------------------------------------------------

    def __len__(self) -> int:
        return len(self._index)

    def __contains__(self, symbol: object) -> bool:
        return symbol in self._index

    @property
    def anchors(self) -> tuple[Anchor, ...]:
        """Every anchor not forgotten. Read them; change them only through this class."""
        return tuple(self._index)

    def get(self, symbol: str) -> Anchor | None:
        return self._index.get(symbol)

    def find(
        self, symbol: str | None = None, class_name: str | None = None, near: np.ndarray | None = None
    ) -> Anchor | None:
        """Top-down Find: the best anchor for a symbol, or for a class (optionally nearest a point).

        Among candidates, CONFIRMED beats TENTATIVE beats MISSING; then, if ``near`` is given, the
        nearest wins; then the most recently seen.
        """
        if symbol is not None:
            anchor = self._index.get(symbol)
            return None if anchor is None or (class_name is not None and anchor.class_name != class_name) else anchor
        if class_name is None and near is None:
            raise InvalidInputError("find() needs a symbol, a class name or a point to search near.")
        if class_name is not None:
            candidates = [self._index.get(name) for name in self._by_class.get(class_name, ())]
        else:
            candidates = list(self._index)
        point = None if near is None else _point(near, "near")

        def preference(anchor: Anchor | None) -> tuple[float, float, float, str]:
            assert anchor is not None
            distance = 0.0 if point is None else float(np.linalg.norm(anchor.position - point))
            return (_FIND_STATE_RANK.get(anchor.state, 3), distance, -anchor.last_seen, anchor.symbol)

        return min(candidates, key=preference, default=None)

    # --- the frame loop ---------------------------------------------------------------------

    def process(self, percepts: Sequence[Percept], camera: CameraView | None, stamp: float) -> AnchoringResult:
        """Anchor one frame's percepts; ``camera`` (or None) says what the camera could see."""
        self._check_percepts(percepts, stamp)
        changes = _Changes(stamp)
        self._latest_stamp = max(self._latest_stamp, stamp)
        self._expire_missing(changes)

        table = self._table_builder.build(percepts, self._index)
        percepts = table.percepts
        assignment = assign(table.scores, self.config.match_threshold)
        symbols = [""] * len(percepts)
        seen: set[str] = set()
        partial = partial_views(percepts, camera, self.config.partial_view)
        for row, column in assignment.matches:
            anchor = table.anchors[column]
            self._reacquire(anchor, percepts[row], changes, continued=bool(table.continuations[row, column]),
                            partial=partial[row])
            symbols[row] = anchor.symbol
            seen.add(anchor.symbol)

        unmatched = [int(row) for row in assignment.unmatched_percepts]
        percepts = self._embed_for_gallery(percepts, unmatched)
        for row in unmatched:
            anchor = self._acquire(percepts[row], changes, partial=partial[row])
            symbols[row] = anchor.symbol
            seen.add(anchor.symbol)

        if camera is not None:
            self._check_unseen(camera, seen, changes)
        renamed = self._merge_reappearances(changes)
        if renamed:
            symbols = [renamed.get(symbol, symbol) for symbol in symbols]
            seen = {renamed.get(symbol, symbol) for symbol in seen}
        for symbol in self._visible - seen:
            anchor = self._index.get(symbol)
            if anchor is not None:
                anchor.visible = False
        self._visible = seen
        return changes.result(symbols)

    def track(self, stamp: float, robot_pose: Pose | None = None) -> AnchoringResult:
        """Extend anchors without observation and apply the lifecycle's time-outs.

        Static objects stay where they were seen; an object expected to be carried follows
        ``robot_pose`` (the robot base in the world frame) while the camera does not see it.
        """
        changes = _Changes(stamp)
        self._latest_stamp = max(self._latest_stamp, stamp)
        for symbol in sorted(self._expected):
            anchor = self._index.get(symbol)
            if anchor is None or anchor.expectation is None or anchor.visible:
                continue
            position = anchor.expectation.expected_position(robot_pose)
            if position is not None:
                self._move_to_expected(anchor, position)
        self._expire_missing(changes)
        return changes.result()

    # --- expected effects -------------------------------------------------------------------

    def expect(
        self, symbol: str, expectation: Expectation, robot_pose: Pose | None = None, stamp: float | None = None
    ) -> AnchoringResult:
        """Record where an action expects an anchored object to be (provenance EXPECTED).

        The anchor moves there at once (a carried one when a robot pose is known) so gating and
        Find look in the right place; perception then confirms or retracts it.

        A search for a MISSING anchor first looks at what was anchored while it was missing: an
        object moved while the robot was elsewhere and seen again from afar got a new anchor,
        because nothing said it was the lost one. If exactly one anchor of its class, first seen
        after it went missing (or, if none was, after its last sighting before that) and
        confirmed since (it may be missing again by now), lies in the searched disc, the search
        has found it: that anchor is merged into the sought one, which
        keeps its symbol (see :meth:`_merge_into`). The result holds the events of such a merge
        (none otherwise).
        """
        anchor = self._require(symbol)
        when = self._latest_stamp if stamp is None else stamp
        changes = _Changes(when if math.isfinite(when) else expectation.stamp)
        if expectation.is_search and anchor.state is AnchorState.MISSING:
            found = self._found_by_search(anchor, expectation)
            if found is not None:
                self._merge_into(anchor, found, changes)
                return changes.result()
        anchor.expectation = expectation
        anchor.expectation_confirmed = False
        anchor.missed_frames = 0
        self._expected.add(symbol)
        position = expectation.expected_position(robot_pose)
        if position is not None:
            self._move_to_expected(anchor, position)
        return changes.result()

    def clear_expectation(self, symbol: str) -> None:
        """Drop an expectation that no longer applies (the carrying action ended, a search failed).

        An expectation perception never confirmed was only a prediction: the anchor goes back to
        where it was last perceived.
        """
        anchor = self._require(symbol)
        if anchor.expectation is None:
            return
        if not anchor.expectation_confirmed:
            anchor.position = anchor.perceived_position.copy()
        self._drop_expectation(anchor)
        self._index.refresh(anchor)

    # --- forgetting, snapshots --------------------------------------------------------------

    def forget(self, symbol: str, stamp: float | None = None) -> AnchorEvent:
        """Forget an anchor on request; returns the FORGOTTEN event for the caller to publish."""
        anchor = self._require(symbol)
        anchor.state = AnchorState.FORGOTTEN
        self._remove(anchor)
        when = self._latest_stamp if stamp is None else stamp
        when = when if math.isfinite(when) else 0.0  # nothing processed yet: no better time to give
        return AnchorEvent(AnchorEventKind.FORGOTTEN, symbol, when, {"reason": "requested"})

    def snapshot(self) -> dict[str, Any]:
        """Every anchor as plain, JSON-safe data (see :mod:`.snapshot`)."""
        return {
            "format": SNAPSHOT_FORMAT,
            "version": SNAPSHOT_VERSION,
            "world_frame": self.config.world_frame,
            "stamp": self._latest_stamp if math.isfinite(self._latest_stamp) else None,
            "anchors": [anchor_to_dict(anchor) for anchor in sorted(self._index, key=lambda a: a.symbol)],
        }

    def restore(self, snapshot: Mapping[str, Any]) -> None:
        """Replace every anchor by those of a snapshot (after a restart, before any frame)."""
        if not isinstance(snapshot, Mapping) or snapshot.get("format") != SNAPSHOT_FORMAT:
            raise InvalidInputError(f"Not an anchors snapshot (expected format {SNAPSHOT_FORMAT!r}).")
        if snapshot.get("version") != SNAPSHOT_VERSION:
            raise InvalidInputError(
                f"Anchors snapshot version {snapshot.get('version')!r} is not supported "
                f"(this code reads version {SNAPSHOT_VERSION})."
            )
        if snapshot.get("world_frame", self.config.world_frame) != self.config.world_frame:
            raise InvalidInputError(
                f"The snapshot's anchors are in frame {snapshot['world_frame']!r}, this core anchors in "
                f"{self.config.world_frame!r}; positions would be meaningless."
            )
        anchors = [anchor_from_dict(data) for data in snapshot.get("anchors", ())]
        symbols = [anchor.symbol for anchor in anchors]
        if len(set(symbols)) != len(symbols):
            raise InvalidInputError("The anchors snapshot names a symbol twice.")
        self._index.clear()
        self._by_class.clear()
        self._missing.clear()
        self._expected.clear()
        self._visible.clear()
        for anchor in anchors:
            if anchor.state is not AnchorState.FORGOTTEN:
                self._insert(anchor)
        self._index.rebuild()
        if snapshot.get("stamp") is not None:
            self._latest_stamp = max(self._latest_stamp, float(snapshot["stamp"]))
        if self._own_counter is not None:
            self._own_counter.note_used(symbols)

    # --- internals: acquire / reacquire -----------------------------------------------------

    def _acquire(self, percept: Percept, changes: _Changes, partial: bool = False) -> Anchor:
        symbol = self._new_symbol(percept.class_name)
        if symbol in self._index:
            raise SailorError(
                f"The symbol factory returned {symbol!r}, which already names an anchor; it must never reuse a "
                "symbol (use a persistent counter such as KnowledgeBase.new_symbol)."
            )
        anchor = Anchor.from_percept(symbol, percept, percept.embedding, self.config.fusion, partial)
        became_confirmed = after_sighting(anchor, self.config.lifecycle)
        self._insert(anchor)
        changes.acquired.append(anchor)
        changes.event(AnchorEventKind.ACQUIRED, symbol, class_name=anchor.class_name, tracker_id=percept.tracker_id,
                      at=_position_text(anchor.position))
        if became_confirmed:
            changes.event(AnchorEventKind.CONFIRMED, symbol, reason="seen", times_seen=anchor.times_seen)
            changes.confirmed_newcomers.append(anchor)
        return anchor

    def _reacquire(
        self, anchor: Anchor, percept: Percept, changes: _Changes, continued: bool, partial: bool = False
    ) -> None:
        # A search for a missing anchor ends only once the anchor is back (see after_sighting):
        # one false detection in the searched disc must not end the search.
        searching = anchor.expectation is not None and anchor.expectation.is_search
        if anchor.expectation is not None and not searching:
            self._resolve_expectation(anchor, percept, changes)
        was_missing = anchor.state is AnchorState.MISSING
        missing_since = anchor.missing_since
        old_class = anchor.class_name
        partial = partial or smaller_than_known(percept, anchor)
        anchor.absorb(percept, percept.embedding, self.config.fusion, partial)
        became_confirmed = after_sighting(anchor, self.config.lifecycle)
        if anchor.state is AnchorState.MISSING:
            anchor.missing_since = missing_since  # not back yet: still on the clock that forgets it
        else:
            self._missing.discard(anchor.symbol)
            if searching:
                self._resolve_expectation(anchor, percept, changes)
        self._index.refresh(anchor)
        if anchor.class_name != old_class:
            self._by_class[old_class].discard(anchor.symbol)
            self._by_class.setdefault(anchor.class_name, set()).add(anchor.symbol)
        changes.reacquired.append(anchor)
        changes.event(
            AnchorEventKind.REACQUIRED,
            anchor.symbol,
            was_missing=was_missing,
            tracker_id=percept.tracker_id,
            tracker_continued=continued,
        )
        if became_confirmed:
            changes.event(AnchorEventKind.CONFIRMED, anchor.symbol, reason="seen", times_seen=anchor.times_seen)
            if not was_missing:
                changes.confirmed_newcomers.append(anchor)

    def _resolve_expectation(self, anchor: Anchor, percept: Percept, changes: _Changes) -> None:
        """Perception outranks expectation: seen near the expected place confirms, elsewhere retracts."""
        expectation = anchor.expectation
        assert expectation is not None
        distance = float(np.linalg.norm(np.asarray(percept.position) - anchor.position))
        details = {"expectation": expectation.describe(), "distance": distance}
        if distance > self.config.expectation_tolerance + expectation.radius:
            changes.event(AnchorEventKind.RETRACTED, anchor.symbol, reason="seen elsewhere", **details)
            self._drop_expectation(anchor)
            anchor.position = anchor.perceived_position.copy()
            return
        if not anchor.expectation_confirmed:
            changes.event(AnchorEventKind.CONFIRMED, anchor.symbol, reason="expectation", **details)
        if expectation.kind is ExpectationKind.CARRIED:
            anchor.expectation_confirmed = True  # still carried: keep following the robot
        else:
            self._drop_expectation(anchor)

    def _embed_for_gallery(self, percepts: tuple[Percept, ...], rows: list[int]) -> tuple[Percept, ...]:
        """Embed new anchors' crops (not yet embedded) so their galleries can be matched later."""
        if not self.matcher.uses_appearance or self.embedder is None:
            return percepts
        needed = [row for row in rows if percepts[row].embedding is None and percepts[row].crop.size > 0]
        return with_embeddings(percepts, needed, self.embedder) if needed else percepts

    # --- internals: top-down search ----------------------------------------------------------

    def _found_by_search(self, sought: Anchor, search: Expectation) -> Anchor | None:
        """The one anchor a search for ``sought`` explains: not tentative, same class, inside the
        searched disc, (when both have galleries) looking alike, and born after it went missing;
        failing that, born after its last sighting before it went missing (the object may have
        been moved and seen anew before its old place was found empty)."""
        since_missing = sought.missing_since if sought.missing_since is not None else sought.last_seen
        since_last_sighting = min(since_missing, sought.lost_after if sought.lost_after is not None else since_missing)
        candidates = self._search_candidates(sought, search, since_last_sighting)
        born_while_missing = [anchor for anchor in candidates if anchor.first_seen >= since_missing]
        chosen = born_while_missing or candidates
        return chosen[0] if len(chosen) == 1 else None

    def _search_candidates(self, sought: Anchor, search: Expectation, born_since: float) -> list[Anchor]:
        reach = search.radius + self.config.expectation_tolerance
        return [
            anchor
            for anchor in self._index
            if anchor is not sought
            and anchor.class_name == sought.class_name
            and anchor.first_seen >= born_since
            # Confirmed, or confirmed once and missing since (its place not in view, the object
            # missed a few frames); a tentative one is too often a false detection.
            and anchor.state in (AnchorState.CONFIRMED, AnchorState.MISSING)
            and anchor.expectation is None
            and float(np.linalg.norm(anchor.position[:2] - search.position[:2])) <= reach
            and self._look_alike(sought, anchor)
        ]

    def _look_alike(self, first: Anchor, second: Anchor) -> bool:
        """Appearance does not rule the pair out (unknown appearance rules nothing out)."""
        if first.gallery is None or second.gallery is None or not len(first.gallery) or not len(second.gallery):
            return True
        return gallery_similarity(first.gallery, second.gallery) >= self.config.merge_similarity

    # --- internals: a missing object reappearing --------------------------------------------

    def _merge_reappearances(self, changes: _Changes) -> dict[str, str]:
        """Merge newcomers that are missing anchors seen again; return {newcomer: kept symbol}.

        Two percepts of one class can compete for one anchor in a frame (a false detection whose
        large box forgives its distance, next to the real object; the near end of a bicycle next
        to its whole); the real one then becomes a new anchor, which wins every later frame
        while the old one, unseen, goes MISSING: a duplicate the knowledge base would keep. The
        newcomer is that object if it was confirmed within ``reappearance_distance`` (beyond
        what a large object's extent explains, as in matching) of a MISSING anchor of its class
        that has not been seen since the newcomer was born, and each is the only candidate of
        the other. Checked when a newcomer is confirmed and when an anchor goes missing,
        whichever comes last.
        """
        if self.config.reappearance_distance <= 0.0:
            return {}
        lost_candidates = {anchor.symbol: anchor for anchor in changes.missing}
        for newcomer in changes.confirmed_newcomers:
            for anchor in self._within_reappearance_distance(newcomer):
                if anchor.state is AnchorState.MISSING:
                    lost_candidates.setdefault(anchor.symbol, anchor)
        renamed: dict[str, str] = {}
        for symbol in sorted(lost_candidates):
            lost = self._index.get(symbol)
            found = None if lost is None else self._reappeared_as(lost)
            if lost is not None and found is not None:
                self._merge_into(lost, found, changes, reason="reappeared where it went missing", moved=False)
                renamed[found.symbol] = lost.symbol
        return renamed

    def _reappeared_as(self, lost: Anchor) -> Anchor | None:
        """The one confirmed newcomer that is ``lost`` seen again, if exactly one is."""
        if lost.state is not AnchorState.MISSING or lost.expectation is not None:
            return None
        candidates = [
            anchor for anchor in self._within_reappearance_distance(lost)
            if anchor.state is AnchorState.CONFIRMED and self._may_be_reappearance(lost, anchor)
        ]
        if len(candidates) != 1:
            return None
        newcomer = candidates[0]
        rivals = [
            anchor for anchor in self._within_reappearance_distance(newcomer)
            if anchor.state is AnchorState.MISSING and anchor.expectation is None
            and self._may_be_reappearance(anchor, newcomer)
        ]
        return newcomer if rivals == [lost] else None

    def _may_be_reappearance(self, lost: Anchor, newcomer: Anchor) -> bool:
        """Same class, born no earlier than ``lost`` was last seen (so never seen apart from it
        in two frames), nothing expected of it, and not ruled out by appearance."""
        return (
            newcomer is not lost
            and newcomer.class_name == lost.class_name
            and newcomer.first_seen >= lost.last_seen
            and newcomer.expectation is None
            and self._look_alike(lost, newcomer)
        )

    def _within_reappearance_distance(self, anchor: Anchor) -> list[Anchor]:
        """Other anchors whose centre lies within the reappearance distance of this one's, plus
        what either's extent explains (views of a large object are not centred alike)."""
        reach = self.config.reappearance_distance
        own_slack = float(extent_slack(anchor.size))
        radius = reach + max(own_slack, self._index.largest_extent_slack())
        slots = self._index.within(anchor.position.reshape(1, 3), radius)[0]
        distance = np.linalg.norm(self._index.positions_of(slots) - anchor.position, axis=1)
        slack = np.maximum(self._index.extent_slacks_of(slots), own_slack)
        return [other for other in self._index.anchors_at(slots[distance - slack <= reach]) if other is not anchor]

    def _merge_into(
        self, kept: Anchor, merged: Anchor, changes: _Changes, reason: str = "found by search", moved: bool = True
    ) -> None:
        """``merged`` was ``kept`` all along: ``kept`` takes its observations and state, ``merged``
        goes (``moved``: the object was found elsewhere, see :meth:`Anchor.absorb_anchor`). A
        ``merged`` that is missing leaves ``kept`` missing, on ``merged``'s clock: the object was
        last seen under that symbol, and seeing it again confirms it as usual."""
        still_missing = merged.state is AnchorState.MISSING
        kept.absorb_anchor(merged, self.config.fusion, moved)
        self._remove(merged)
        kept.expectation = None
        kept.expectation_confirmed = False
        self._expected.discard(kept.symbol)
        kept.state = AnchorState.MISSING if still_missing else AnchorState.CONFIRMED
        kept.missing_since = merged.missing_since if still_missing else None
        kept.lost_after = merged.lost_after if still_missing else None
        kept.missed_frames = merged.missed_frames if still_missing else 0
        kept.recovery_sightings = merged.recovery_sightings if still_missing else 0
        merged.state = AnchorState.FORGOTTEN
        if still_missing:
            self._missing.add(kept.symbol)
        else:
            self._missing.discard(kept.symbol)
        self._index.refresh(kept)
        if kept.visible:
            self._visible.add(kept.symbol)
        changes.forgotten.append(merged)
        changes.reacquired.append(kept)
        changes.event(AnchorEventKind.FORGOTTEN, merged.symbol, reason=f"{reason}: it is {kept.symbol}")
        if not still_missing:
            changes.event(AnchorEventKind.CONFIRMED, kept.symbol, reason=reason, merged=merged.symbol)

    # --- internals: lifecycle ---------------------------------------------------------------

    def _check_unseen(self, camera: CameraView, seen: set[str], changes: _Changes) -> None:
        """Count anchors that should have been seen but were not; retract expectations seen empty."""
        slots = self._index.within(camera.position.reshape(1, 3), _frustum_reach(camera, self.config.visibility))[0]
        anchors = [anchor for anchor in self._index.anchors_at(slots) if anchor.symbol not in seen]
        if not anchors:
            return
        visible = should_be_visible(
            np.array([a.position for a in anchors]), np.array([a.size for a in anchors]), camera, self.config.visibility
        )
        for anchor in (a for a, expected in zip(anchors, visible, strict=True) if expected):
            if anchor.expectation is not None and anchor.expectation.is_search:
                continue  # the searcher decides when a search has failed
            if anchor.expectation is not None:
                changes.event(
                    AnchorEventKind.RETRACTED,
                    anchor.symbol,
                    reason="expected place seen empty",
                    expectation=anchor.expectation.describe(),
                )
                self._drop_expectation(anchor)
                anchor.position = anchor.perceived_position.copy()
                self._index.refresh(anchor)
            elif after_expected_but_unseen(anchor, changes.stamp, self.config.lifecycle):
                self._missing.add(anchor.symbol)
                changes.missing.append(anchor)
                changes.event(AnchorEventKind.MISSING, anchor.symbol, missed_frames=anchor.missed_frames)
            elif anchor.missing_since is not None:
                self._missing.add(anchor.symbol)  # a tentative anchor not seen where it should be: to forget

    def _expire_missing(self, changes: _Changes) -> None:
        for symbol in sorted(self._missing):
            anchor = self._index.get(symbol)
            if anchor is not None and expire(anchor, changes.stamp, self.config.lifecycle):
                self._remove(anchor)
                changes.forgotten.append(anchor)
                changes.event(
                    AnchorEventKind.FORGOTTEN, symbol, reason="missing too long", missing_since=anchor.missing_since
                )

    # --- internals: bookkeeping -------------------------------------------------------------

    def _move_to_expected(self, anchor: Anchor, position: np.ndarray) -> None:
        anchor.position = np.asarray(position, dtype=np.float64)
        anchor.position_variance = self.config.expectation_tolerance**2
        anchor.provenance = Provenance.EXPECTED
        self._index.refresh(anchor)

    def _drop_expectation(self, anchor: Anchor) -> None:
        anchor.expectation = None
        anchor.expectation_confirmed = False
        anchor.provenance = Provenance.PERCEIVED
        self._expected.discard(anchor.symbol)

    def _insert(self, anchor: Anchor) -> None:
        self._index.add(anchor)
        self._by_class.setdefault(anchor.class_name, set()).add(anchor.symbol)
        if anchor.state is AnchorState.MISSING or anchor.missing_since is not None:
            self._missing.add(anchor.symbol)
        if anchor.expectation is not None:
            self._expected.add(anchor.symbol)
        if anchor.visible:
            self._visible.add(anchor.symbol)

    def _remove(self, anchor: Anchor) -> None:
        self._index.remove(anchor.symbol)
        self._by_class.get(anchor.class_name, set()).discard(anchor.symbol)
        self._missing.discard(anchor.symbol)
        self._expected.discard(anchor.symbol)
        self._visible.discard(anchor.symbol)
        anchor.visible = False

    def _require(self, symbol: str) -> Anchor:
        anchor = self._index.get(symbol)
        if anchor is None:
            raise InvalidInputError(f"No anchor is named {symbol!r}; it was never acquired or has been forgotten.")
        return anchor

    def _check_percepts(self, percepts: Iterable[Percept], stamp: float) -> None:
        if not math.isfinite(stamp):
            raise InvalidInputError(f"The frame stamp must be finite, got {stamp}.")
        for number, percept in enumerate(percepts):
            if percept.frame_id != self.config.world_frame:
                raise InvalidInputError(
                    f"Percept {number} ({percept.class_name}) is in frame {percept.frame_id!r}, but anchors live in "
                    f"{self.config.world_frame!r}; transform percepts with the camera pose at the image stamp first."
                )
            _point(percept.position, f"percept {number} position")
            size = np.asarray(percept.size, dtype=np.float64).reshape(-1)
            if size.shape != (3,) or not np.all(np.isfinite(size)) or np.any(size < 0.0):
                raise InvalidInputError(
                    f"Percept {number} size must be 3 finite non-negative numbers, got {size.tolist()}."
                )
            if not math.isfinite(percept.stamp):
                raise InvalidInputError(f"Percept {number} has a non-finite stamp {percept.stamp}.")
            try:  # checked here, before anything changes, not when a symbol is made mid-frame
                to_identifier(percept.class_name)
            except KnowledgeError as error:
                raise InvalidInputError(
                    f"Percept {number} has a class name {percept.class_name!r} no symbol can be made from: {error}"
                ) from error


def _point(values: Any, name: str) -> np.ndarray:
    point = np.asarray(values, dtype=np.float64).reshape(-1)
    if point.shape != (3,) or not np.all(np.isfinite(point)):
        raise InvalidInputError(f"{name} must be 3 finite coordinates, got {np.asarray(values).tolist()}.")
    return point


def _frustum_reach(camera: CameraView, config: VisibilityConfig) -> float:
    """The largest distance from the optical centre of any point inside the frustum."""
    intrinsics = camera.intrinsics
    half_width = max(intrinsics.cx, intrinsics.width - intrinsics.cx) / intrinsics.fx
    half_height = max(intrinsics.cy, intrinsics.height - intrinsics.cy) / intrinsics.fy
    return config.frustum.far * math.sqrt(1.0 + half_width**2 + half_height**2)


def _position_text(position: np.ndarray) -> str:
    """A position as people read it in a log line: where an object was first seen says much about why."""
    return "(" + ", ".join(f"{float(value):.2f}" for value in position) + ")"
