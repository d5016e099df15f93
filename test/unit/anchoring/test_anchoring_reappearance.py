"""A missing object seen again under a new symbol is merged back into its first anchor.

The case comes from a mission run: a book on a desk, seen from a doorway, went missing while
the robot drove out of depth range; when it came back in range, a false detection with a large
box (which forgives its distance, see ``features.extent_slack``) took the missing anchor in the
same frame as the real book, so the book got a new anchor and the knowledge base kept the old
one as ``missing`` for good.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from merlin2_sailor.anchoring import AnchorEventKind, Anchoring, AnchoringConfig, AnchorState, LifecycleConfig
from merlin2_sailor.anchoring.anchor_index import AnchorIndex
from merlin2_sailor.anchoring.colour_evidence import ColourEvidenceConfig, colour_evidence_grew, with_view
from merlin2_sailor.anchoring.identity_repair import IdentityRepair, RepairConfig, Undecided
from merlin2_sailor.anchoring.matcher_registry import MatcherSettings, create_matcher
from merlin2_sailor.anchoring.rule_matcher import RuleMatcher, RuleMatcherConfig
from merlin2_sailor.anchoring.snapshot import anchors_of_snapshot
from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.errors import ConfigurationError

from .anchoring_scenes import AppearanceRules, PerceptMaker, SceneObject, camera_view, mug_colour

FRAME = 1.0 / 15.0
BOOK = SceneObject("desk_book", "book", (3.0, 0.2, 0.9), (0.05, 0.2, 0.26))
#: A false detection's box over the desk and the wall: a metre wide, centred a little off the book.
FALSE_BOOK = SceneObject("false_book", "book", (3.1, 0.0, 0.9), (0.9, 0.9, 0.9))


def see(anchoring, percepts, stamp):
    return anchoring.process(percepts, camera_view(), stamp)


def books(anchoring):
    return sorted((anchor.symbol, anchor.state) for anchor in anchoring.anchors)


def test_a_newcomer_confirmed_where_an_anchor_went_missing_is_that_anchor(make_anchoring, maker):
    anchoring = make_anchoring()  # confirmed after 2 sightings, missing after 1 missed frame
    for frame in range(2):
        see(anchoring, [maker.percept(BOOK, frame * FRAME)], frame * FRAME)
    see(anchoring, [], 1.0)  # out of depth range: the detection is dropped
    assert books(anchoring) == [("book_1", AnchorState.MISSING)]

    # Back in range 3 s later: the false detection takes the missing anchor, the book a new one.
    first = see(anchoring, [maker.percept(BOOK, 4.0), maker.percept(FALSE_BOOK, 4.0)], 4.0)
    assert first.percept_symbols == ("book_2", "book_1")

    second = see(anchoring, [maker.percept(BOOK, 4.0 + FRAME)], 4.0 + FRAME)
    assert books(anchoring) == [("book_1", AnchorState.CONFIRMED)]
    assert second.percept_symbols == ("book_1",)
    assert [(event.kind, event.symbol, event.details.get("reason")) for event in second.events][-2:] == [
        (AnchorEventKind.FORGOTTEN, "book_2", "reappeared where it went missing: it is book_1"),
        (AnchorEventKind.CONFIRMED, "book_1", "reappeared where it went missing"),
    ]
    kept = anchoring.get("book_1")
    np.testing.assert_allclose(kept.position, BOOK.position, atol=0.05)
    assert kept.missing_since is None and kept.visible
    assert see(anchoring, [maker.percept(BOOK, 5.0)], 5.0).percept_symbols == ("book_1",)


def test_the_anchor_going_missing_after_its_newcomer_was_confirmed_is_merged_too(maker):
    """With the default lifecycle the newcomer is confirmed (3 sightings) before the anchor whose
    percept it took is missing (3 missed frames): the merge happens when the second of the two
    comes true. (The place-return rule, which would undo the false detection's pull at once, is
    off here: this is the reappearance rule's case when the pull is slower; see the next test.)"""
    anchoring = Anchoring(AnchoringConfig(repair=RepairConfig(place_jump=0.0)))
    for frame in range(3):
        see(anchoring, [maker.percept(BOOK, frame * FRAME)], frame * FRAME)
    stamp = 20.0
    see(anchoring, [maker.percept(BOOK, stamp), maker.percept(FALSE_BOOK, stamp)], stamp)
    assert {anchor.symbol for anchor in anchoring.anchors} == {"book_1", "book_2"}
    merged_at = None
    for frame in range(1, 5):
        stamp = 20.0 + frame * FRAME
        result = see(anchoring, [maker.percept(BOOK, stamp)], stamp)
        if any(event.kind is AnchorEventKind.FORGOTTEN for event in result.events):
            merged_at = frame
            break
    assert merged_at == 3  # book_2 confirmed at frame 2, book_1 missing at frame 3
    assert books(anchoring) == [("book_1", AnchorState.CONFIRMED)]
    assert result.percept_symbols == ("book_1",)


def test_a_false_detection_pulling_a_confirmed_anchor_away_is_undone_in_the_same_frame(maker):
    """The same frames with every rule on: the anchor, still confirmed, jumped to the false box
    and the book was acquired on the place it left, so the two trade places at once."""
    anchoring = Anchoring(AnchoringConfig())
    for frame in range(3):
        see(anchoring, [maker.percept(BOOK, frame * FRAME)], frame * FRAME)
    first = see(anchoring, [maker.percept(BOOK, 20.0), maker.percept(FALSE_BOOK, 20.0)], 20.0)
    assert first.percept_symbols == ("book_1", "book_2")
    np.testing.assert_allclose(anchoring.get("book_1").position, BOOK.position, atol=0.05)
    for frame in range(1, 40):
        stamp = 20.0 + frame * FRAME
        assert see(anchoring, [maker.percept(BOOK, stamp)], stamp).percept_symbols == ("book_1",)
    assert books(anchoring) == [("book_1", AnchorState.CONFIRMED)]  # the false box's anchor was never confirmed


def desk_book(share: float, hue: int = 12) -> SceneObject:
    return SceneObject("desk_book", "book", BOOK.position, BOOK.size, colour=mug_colour(hue, share=share))


def book_seen_again_in_colours(shares: list[float], hue: int = 12) -> tuple[Anchoring, list]:
    """A desk book seen whole 6 times (its cover's hue on 0.3 of its pixels); 20 s later, views of
    what stands in its place with the given shares of that hue (far views show less of it, near
    ones more); returns the anchoring and every event after the absence."""
    lifecycle = LifecycleConfig(confirm_after=2, missed_frames_to_missing=1, forget_after=600.0)
    anchoring, maker, stamp, events = Anchoring(AnchoringConfig(lifecycle=lifecycle)), PerceptMaker(seed=1), 0.0, []
    for _ in range(6):
        anchoring.process([maker.percept(desk_book(0.3), stamp)], camera_view(), stamp)
        stamp += FRAME
    stamp += 20.0
    for share in shares:
        events.extend(anchoring.process([maker.percept(desk_book(share, hue), stamp)], camera_view(), stamp).events)
        stamp += FRAME
    return anchoring, events


@pytest.mark.parametrize("shares", [
    [0.12, 0.12, 0.48, 0.12, 0.48, 0.12, 0.48, 0.12, 0.48],  # first from afar, then near and far in turn
    [0.48, 0.48, 0.12, 0.48, 0.12, 0.48, 0.12, 0.48, 0.12],  # first near, then in turn
    [0.15, 0.15, 0.15, 0.45, 0.45, 0.45, 0.15, 0.45, 0.15, 0.45, 0.15, 0.45],  # known only at the second judging
])
def test_a_newcomer_is_judged_again_as_its_colour_evidence_grows(shares):
    """From the scenario suite (`removed`, both matchers, seed 2): the desk book, seen again from
    afar, differed in colour from its lost anchor's few views, so it was anchored anew and the
    reappearance was refused; its later views agreed with the lost anchor, but nothing judged it
    again, and the book kept two anchors. Every view here differs from the lost anchor's narrow
    colour (each is gated from it), while the views together agree with it: once the newcomer's
    colour is known, or has doubled its views, the two are one book."""
    anchoring, events = book_seen_again_in_colours(shares)
    assert books(anchoring) == [("book_1", AnchorState.CONFIRMED)]
    assert any(e.kind is AnchorEventKind.FORGOTTEN and e.symbol == "book_2" for e in events)


@pytest.mark.parametrize(("share", "hue"), [(0.6, 12), (0.3, 6), (0.12, 12), (0.5, 12)])
def test_a_book_of_another_colour_in_its_place_is_never_judged_the_lost_one(share, hue):
    """Differences of 0.2 to 0.3 in a window (more than one object's own views differ by): decided,
    the lost book stays missing, and no doubt is raised."""
    anchoring, events = book_seen_again_in_colours([share] * 14, hue)
    assert books(anchoring) == [("book_1", AnchorState.MISSING), ("book_2", AnchorState.CONFIRMED)]
    assert anchoring.get("book_1").indistinguishable_from == ()
    assert not any(event.kind is AnchorEventKind.AMBIGUOUS for event in events)


@pytest.mark.parametrize("share", [0.42, 0.45, 0.16, 0.14])
def test_a_colour_differing_as_little_as_one_objects_views_do_leaves_a_reappearance_undecided(share):
    """From the scenario suite (`large_object_wheeled_away`, network, seeds 0 and 1): a bird known
    from one glance, seen again in its place 86 s later 0.11 off in one hue window, was anchored
    anew beside its own missing anchor. A difference of 0.12-0.16 in the cover's hue (more of it or
    less) is within what one object's views differ by: the lost book is not merged, nor silently
    left as another book; it stays missing and names the newcomer it cannot be told from, and an
    AMBIGUOUS event says why. (0.18 and more decide: the test above.)"""
    anchoring, events = book_seen_again_in_colours([share] * 14)
    assert books(anchoring) == [("book_1", AnchorState.MISSING), ("book_2", AnchorState.CONFIRMED)]
    assert anchoring.get("book_1").indistinguishable_from == ("book_2",)
    ambiguous = [event for event in events if event.kind is AnchorEventKind.AMBIGUOUS]
    assert [(event.symbol, event.details["candidates"]) for event in ambiguous] == [("book_1", "book_2")]
    assert "no more than one object's own views do" in ambiguous[0].details["reason"]


def test_colour_evidence_grows_when_known_and_at_each_doubling():
    model, grew = None, []
    for view in range(1, 26):
        model = with_view(model, mug_colour(12))
        if colour_evidence_grew(model, 3):
            grew.append(view)
    assert grew == [3, 6, 12, 24]
    assert not colour_evidence_grew(model, 0) and not colour_evidence_grew(None, 3)


def test_two_objects_seen_apart_are_never_merged(make_anchoring, maker):
    """Two books side by side, both seen in the same frames: when one goes missing, the other is
    not it, however near (it was seen while the lost one still was)."""
    anchoring = make_anchoring()
    neighbour = SceneObject("neighbour", "book", (3.0, 0.4, 0.9), (0.05, 0.2, 0.26))
    for frame in range(3):
        see(anchoring, [maker.percept(BOOK, frame * FRAME), maker.percept(neighbour, frame * FRAME)], frame * FRAME)
    see(anchoring, [maker.percept(neighbour, 1.0)], 1.0)
    assert books(anchoring) == [("book_1", AnchorState.MISSING), ("book_2", AnchorState.CONFIRMED)]


@pytest.mark.parametrize(("offset", "merged"), [(0.1, True), (0.45, False)])
def test_only_a_newcomer_within_the_reappearance_distance_is_merged(make_anchoring, maker, offset, merged):
    """The false detection takes the missing anchor and the book, back beside its old place, is
    anchored anew: 0.1 m away it is taken for the missing one (which the false box pulled 0.1 m
    the other way), 0.45 m away (farther than the 0.25 m reappearance distance) it is not. A
    cup seen at the book's very place never is."""
    anchoring = make_anchoring()
    for frame in range(2):
        see(anchoring, [maker.percept(BOOK, frame * FRAME)], frame * FRAME)
    see(anchoring, [], 1.0)
    beside = np.array(BOOK.position) + (0.0, offset, 0.0)
    cup = SceneObject("cup", "cup", BOOK.position)
    see(anchoring, [maker.percept(BOOK, 4.0, position=beside), maker.percept(FALSE_BOOK, 4.0),
                    maker.percept(cup, 4.0)], 4.0)
    for frame in range(1, 3):
        stamp = 4.0 + frame * FRAME
        see(anchoring, [maker.percept(BOOK, stamp, position=beside), maker.percept(cup, stamp)], stamp)
    states = {anchor.symbol: anchor.state for anchor in anchoring.anchors}
    if merged:
        assert states == {"book_1": AnchorState.CONFIRMED, "cup_1": AnchorState.CONFIRMED}
    else:
        assert states == {"book_1": AnchorState.MISSING, "book_2": AnchorState.CONFIRMED,
                          "cup_1": AnchorState.CONFIRMED}


class PlaceStrict(AppearanceRules):
    """Appearance times rules that take a view more than 0.1 m off for another object."""

    def __init__(self) -> None:
        super().__init__()
        self.rules = RuleMatcher(RuleMatcherConfig(position_sigma=0.1, drift_speed=0.0, maximum_sigma=0.1))


@pytest.mark.parametrize(("looks_like", "merged"), [("", True), ("another_book", False)])
@pytest.mark.parametrize("offset", [(0.0, 0.2, 0.0), (0.15, -0.1, 0.0)])
def test_the_merge_judges_the_look_and_leaves_the_place_to_the_rule(maker, looks_like, merged, offset):
    """The rule itself bounds the place (the reappearance distance); the matching function is
    asked everything else. With a matcher strict about place (0.1 m), a book anchored 0.2 m from
    a missing one, as a pose correction puts it, is merged when it looks the same, never when it
    looks like another book (as a learned matcher tells them: scenario suite, `swapped`, network,
    seed 1, 5 December 2026, where the place alone kept the cookbook under two symbols)."""
    anchoring = Anchoring(AnchoringConfig(lifecycle=LifecycleConfig(confirm_after=2, missed_frames_to_missing=1)),
                          PlaceStrict())
    for frame in range(2):
        see(anchoring, [maker.percept(BOOK, frame * FRAME)], frame * FRAME)
    see(anchoring, [], 1.0)
    beside = SceneObject(BOOK.identity, BOOK.class_name, tuple(np.add(BOOK.position, offset).tolist()), BOOK.size,
                         looks_like=looks_like)
    for frame in range(3):
        stamp = 2.0 + frame * FRAME
        see(anchoring, [maker.percept(beside, stamp)], stamp)
    if merged:
        assert books(anchoring) == [("book_1", AnchorState.CONFIRMED)]
    else:
        assert books(anchoring) == [("book_1", AnchorState.MISSING), ("book_2", AnchorState.CONFIRMED)]


def test_a_large_object_seen_again_in_part_is_merged_and_keeps_its_whole_view(make_anchoring, maker):
    """The near end of a bicycle, cut by the image's edge, is centred 0.8 m from the whole
    bicycle's centre: its extent explains that, as in matching. When a false detection takes the
    missing anchor in the frame the near end comes back, the near end is anchored anew, then
    merged; the merged anchor keeps the centre and size of its whole views (a part says less)."""
    anchoring = make_anchoring()
    bicycle = SceneObject("bicycle", "bicycle", (3.0, 0.0, 0.5), (0.35, 1.6, 1.0))
    near_end = SceneObject("bicycle_end", "bicycle", (3.0, -0.8, 0.5), (0.27, 0.08, 1.0))
    false_bicycle = SceneObject("false_bicycle", "bicycle", (3.1, 0.1, 0.5), (0.4, 1.6, 1.0))
    for frame in range(2):
        see(anchoring, [maker.percept(bicycle, frame * FRAME)], frame * FRAME)
    see(anchoring, [], 1.0)
    at_the_edge = BoundingBox2D(center_x=6.0, center_y=60.0, width=12.0, height=60.0)
    first = see(anchoring, [dataclasses.replace(maker.percept(near_end, 2.0), box=at_the_edge),
                            maker.percept(false_bicycle, 2.0)], 2.0)
    assert first.percept_symbols == ("bicycle_2", "bicycle_1")
    see(anchoring, [dataclasses.replace(maker.percept(near_end, 2.0 + FRAME), box=at_the_edge)], 2.0 + FRAME)
    assert books(anchoring) == [("bicycle_1", AnchorState.CONFIRMED)]
    kept = anchoring.get("bicycle_1")
    np.testing.assert_allclose(kept.position, bicycle.position, atol=0.15)
    np.testing.assert_allclose(kept.size, bicycle.size, rtol=0.1)
    assert kept.times_seen == 5


def test_the_reappearance_merge_can_be_turned_off_and_is_validated(maker):
    anchoring = Anchoring(AnchoringConfig(
        repair=RepairConfig(reappearance_distance=0.0),
        lifecycle=LifecycleConfig(confirm_after=2, missed_frames_to_missing=1)))
    for frame in range(2):
        see(anchoring, [maker.percept(BOOK, frame * FRAME)], frame * FRAME)
    see(anchoring, [], 1.0)
    see(anchoring, [maker.percept(BOOK, 4.0), maker.percept(FALSE_BOOK, 4.0)], 4.0)
    see(anchoring, [maker.percept(BOOK, 4.0 + FRAME)], 4.0 + FRAME)
    assert len(anchoring) == 2
    with pytest.raises(ConfigurationError, match="reappearance_distance"):
        RepairConfig(reappearance_distance=float("nan"))
    with pytest.raises(ConfigurationError, match="ambiguity_margin"):
        RepairConfig(ambiguity_margin=1.5)


#: The two anchors of one bird at the end of two scenario-suite runs (`large_object_wheeled_away`,
#: network, seeds 0 and 1, 7 December 2026, the anchoring node's snapshot): bird_3, known from three
#: frames of one glance and MISSING, and the newcomer anchored 0.02 m (0.01 m) from it 86 s (92 s)
#: later, its views 0.11 (0.14) off in one hue window.
ONE_GLANCE_BIRD = Path(__file__).parent / "data" / "bird_known_from_one_glance.json"


@pytest.mark.parametrize(("run", "newcomer"), [("seed 0", "bird_6"), ("seed 1", "bird_5")])
@pytest.mark.parametrize("matcher", ["rules", "network"])
def test_the_suites_bird_known_from_one_glance_is_left_undecided_not_anchored_twice(run, newcomer, matcher):
    """The run's own anchors, judged again: the matching function takes the newcomer for the lost
    bird and only the colour, 0.11-0.13 apart, holds them apart, so the reappearance is a doubt the
    lost anchor states. With a doubt level below that gap the colour decides, as it did in the run
    (two birds, nothing said)."""
    if matcher == "network":
        pytest.importorskip("openvino")
    snapshot = json.loads(ONE_GLANCE_BIRD.read_text())[run]
    anchors, _ = anchors_of_snapshot(snapshot, snapshot["world_frame"])
    lost = next(anchor for anchor in anchors if anchor.symbol == "bird_3")
    found = next(anchor for anchor in anchors if anchor.symbol == newcomer)
    assert lost.state is AnchorState.MISSING and found.state is AnchorState.CONFIRMED
    index = AnchorIndex()
    for anchor in anchors:
        index.add(anchor)

    def decide(doubt_level: float):
        colour = ColourEvidenceConfig(minimum_difference_across_sides=doubt_level)
        repair = IdentityRepair(create_matcher(MatcherSettings(name=matcher)), 0.5, RepairConfig(), 0.5, colour)
        return repair.decide_reappearances([lost], [found], index)

    (decision,) = decide(ColourEvidenceConfig().minimum_difference_across_sides)
    assert isinstance(decision, Undecided)
    assert (decision.lost, decision.found) == ((lost,), (found,))
    assert "the colours differ by 0.1" in decision.reason
    assert decide(0.1) == []
