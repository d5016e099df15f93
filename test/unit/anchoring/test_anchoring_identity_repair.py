"""Identity repair decides by the matching function's evidence, appearance included, or not at all.

The matcher here is a small appearance-aware one (the rules, times how alike the two crops'
embeddings are), so these tests exercise the repair logic that any appearance matcher, the
learned one included, goes through; the rule matcher cannot tell a green mug from a blue one,
and is covered by the search and reappearance tests beside this file.

Situations: a look-alike moved while its twin stays; an object removed while another of its
class, another colour, is seen in the searched room; two look-alikes found for one lost mug;
two lost look-alikes and one found; a newcomer of another look beside a missing anchor; a
search that goes on while the object is anchored anew.

The searched rooms here were never watched before their mugs were seen, and no twin of a lost mug
is known by its colour: a search that finds its mug only records the find by look alone
(``found_by_look_alone``; the lost anchor stays MISSING) and takes it when it concludes, having
looked everywhere (``Anchoring.conclude_search``). A candidate the search rules out is neither
recorded nor taken then.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from merlin2_sailor.anchoring import AnchorEventKind, Anchoring, AnchoringConfig, AnchorState, Expectation
from merlin2_sailor.anchoring.anchor import Anchor
from merlin2_sailor.anchoring.anchor_comparison import SearchedDisc, identity_scores
from merlin2_sailor.anchoring.anchoring import _involved as involved
from merlin2_sailor.anchoring.fusion import FusionConfig
from merlin2_sailor.anchoring.identity_repair import Undecided
from merlin2_sailor.anchoring.lifecycle import LifecycleConfig
from merlin2_sailor.anchoring.rule_matcher import RuleMatcher

from .anchoring_scenes import AppearanceRules, PerceptMaker, SceneObject, camera_view

FRAME = 1.0 / 15.0
KITCHEN_MUG = SceneObject("blue_mug", "cup", (2.0, 0.3, 0.8))
TWIN = SceneObject("blue_twin", "cup", (2.0, -0.3, 0.8), looks_like="blue_mug")
LIVING_ROOM = np.array((1.5, 6.0, 0.8))
GREEN_MUG = SceneObject("green_mug", "cup", (1.9, 6.2, 0.8))
#: When the robot, having left the kitchen at 1 s, first sees the living room (about 6 m away):
#: late enough for someone to have carried a mug there (RepairConfig.carry_speed).
WALKED_THERE = 10.0


@pytest.fixture
def anchoring() -> Anchoring:
    lifecycle = LifecycleConfig(confirm_after=2, missed_frames_to_missing=1, forget_after=600.0)
    return Anchoring(AnchoringConfig(lifecycle=lifecycle), AppearanceRules())


@pytest.fixture
def maker() -> PerceptMaker:
    return PerceptMaker(seed=11, appearance_noise=0.02)


def see(anchoring, maker, items, stamp, camera=True, positions=None):
    percepts = [maker.percept(item, stamp, position=(positions or {}).get(item.identity)) for item in items]
    return anchoring.process(percepts, camera_view() if camera else None, stamp)


def seen_twice(anchoring, maker, items, start, camera=True, positions=None):
    for frame in range(2):
        see(anchoring, maker, items, start + frame * FRAME, camera, positions)


def symbol_at(anchoring, item):
    """The symbol of the anchor nearest ``item``: new anchors of one frame are numbered by place."""
    return min(anchoring.anchors, key=lambda anchor: np.linalg.norm(anchor.position - item.position)).symbol


def search_living_room(anchoring, symbol, stamp):
    return anchoring.expect(symbol, Expectation.at(LIVING_ROOM, stamp, "living_room", "find", radius=1.5))


def kinds(result):
    return [(event.kind, event.symbol) for event in result.events]


def recorded(anchoring, symbol):
    """The sought anchor's state and the candidate its search found by look alone ("": none)."""
    sought = anchoring.get(symbol)
    return sought.state, sought.found_by_look_alone


def concluded(anchoring, symbol):
    """The search for ``symbol`` has looked everywhere: what concluding it does, as (kind, symbol)."""
    return kinds(anchoring.conclude_search(symbol))


@pytest.mark.parametrize("turning_frames", [6, 8, 11])
def test_a_search_judges_a_newcomer_again_as_its_views_grow(anchoring, maker, turning_frames):
    """The moved mug is first seen in the searched room from its other side, which does not look
    like the views its lost anchor has, then turning into view over ``turning_frames`` frames: the
    search cannot take its new anchor when it is confirmed, but its later views look like the lost
    mug, and the search, judging it again as its sightings double, finds it (test_merlin2_mission,
    network, 5 December 2026: judged only once, the search gave up on a newcomer that its later
    views showed to be the red mug). The living room was never watched: the find is recorded when
    a later judgement makes it, and taken when the search concludes."""
    seen_twice(anchoring, maker, [KITCHEN_MUG], 0.0)
    see(anchoring, maker, [], 1.0)
    assert search_living_room(anchoring, "cup_1", 1.5).events == ()
    other_side, own_side = maker.appearance("the blue mug's other side"), maker.appearance("blue_mug")
    found_at = None
    for frame in range(2 * turning_frames + 4):
        stamp = WALKED_THERE + frame * FRAME
        turned = min(frame / turning_frames, 1.0)
        look = (1.0 - turned) * other_side + turned * own_side
        percept = dataclasses.replace(maker.percept(KITCHEN_MUG, stamp, position=(1.5, 7.2, 0.8)),
                                      embedding=(look / np.linalg.norm(look)).astype(np.float32))
        result = anchoring.process([percept], None, stamp)
        assert not [e for e in result.events if e.kind is AnchorEventKind.FORGOTTEN], "merged before concluding"
        if found_at is None and anchoring.get("cup_1").found_by_look_alone:
            found_at = frame
        if frame == 1:
            assert anchoring.get("cup_2").state is AnchorState.CONFIRMED, "not confirmed yet"
            assert recorded(anchoring, "cup_1") == (AnchorState.MISSING, ""), "found at once"
    assert found_at is not None and found_at > 1, "never judged again"
    assert recorded(anchoring, "cup_1") == (AnchorState.MISSING, "cup_2")
    result = anchoring.conclude_search("cup_1")
    assert kinds(result) == [(AnchorEventKind.FORGOTTEN, "cup_2"), (AnchorEventKind.CONFIRMED, "cup_1")]
    assert result.events[0].details["reason"].endswith("it is cup_1")
    assert anchoring.get("cup_1").state is AnchorState.CONFIRMED and len(anchoring) == 1


def test_a_look_alike_moved_while_its_twin_stays_is_found_under_its_own_symbol(anchoring, maker):
    seen_twice(anchoring, maker, [KITCHEN_MUG, TWIN], 0.0)
    mug, twin = symbol_at(anchoring, KITCHEN_MUG), symbol_at(anchoring, TWIN)
    see(anchoring, maker, [TWIN], 1.0)  # the kitchen: the twin is there, the other mug is not
    assert anchoring.get(mug).state is AnchorState.MISSING
    seen_twice(anchoring, maker, [KITCHEN_MUG], WALKED_THERE, camera=False, positions={"blue_mug": LIVING_ROOM})
    assert search_living_room(anchoring, mug, WALKED_THERE + 1.0).events == ()
    assert recorded(anchoring, mug) == (AnchorState.MISSING, "cup_3")
    assert concluded(anchoring, mug) == [(AnchorEventKind.FORGOTTEN, "cup_3"), (AnchorEventKind.CONFIRMED, mug)]
    np.testing.assert_allclose(anchoring.get(mug).position, LIVING_ROOM, atol=0.05)
    assert anchoring.get(twin).state is AnchorState.CONFIRMED  # the twin keeps its own symbol


def test_a_removed_object_is_never_reported_found_as_another_of_its_class(anchoring, maker):
    seen_twice(anchoring, maker, [KITCHEN_MUG], 0.0)
    see(anchoring, maker, [], 1.0)
    seen_twice(anchoring, maker, [GREEN_MUG], WALKED_THERE, camera=False)  # a green mug, in the searched room
    result = search_living_room(anchoring, "cup_1", WALKED_THERE + 1.0)
    assert result.events == ()
    assert recorded(anchoring, "cup_1") == (AnchorState.MISSING, "")  # not even found by look alone
    assert concluded(anchoring, "cup_1") == []  # so concluding the search takes nothing
    assert anchoring.get("cup_1").state is AnchorState.MISSING
    assert anchoring.get("cup_2").state is AnchorState.CONFIRMED
    # The rules alone cannot tell the two apart: they take the green mug for the lost one.
    rules = Anchoring(AnchoringConfig(lifecycle=anchoring.config.lifecycle), RuleMatcher())
    seen_twice(rules, maker, [KITCHEN_MUG], 0.0)
    see(rules, maker, [], 1.0)
    seen_twice(rules, maker, [GREEN_MUG], WALKED_THERE, camera=False)
    assert search_living_room(rules, "cup_1", WALKED_THERE + 1.0).events == ()
    assert recorded(rules, "cup_1") == (AnchorState.MISSING, "cup_2")
    assert concluded(rules, "cup_1")[0] == (AnchorEventKind.FORGOTTEN, "cup_2")


def test_two_look_alikes_found_for_one_lost_mug_are_reported_not_guessed(anchoring, maker):
    seen_twice(anchoring, maker, [KITCHEN_MUG], 0.0)
    see(anchoring, maker, [], 1.0)
    first = SceneObject("first", "cup", (1.2, 5.6, 0.8), looks_like="blue_mug")
    second = SceneObject("second", "cup", (1.8, 6.4, 0.8), looks_like="blue_mug")
    seen_twice(anchoring, maker, [first, second], WALKED_THERE, camera=False)
    result = search_living_room(anchoring, "cup_1", WALKED_THERE + 1.0)
    assert [(e.kind, e.symbol, e.details["candidates"]) for e in result.events] == [
        (AnchorEventKind.AMBIGUOUS, "cup_1", "cup_2,cup_3")]
    lost = anchoring.get("cup_1")
    assert lost.state is AnchorState.MISSING and lost.indistinguishable_from == ("cup_2", "cup_3")
    assert len(anchoring) == 3
    again = search_living_room(anchoring, "cup_1", WALKED_THERE + 1.5)
    assert again.events == ()  # said once, not every time the search is renewed


def test_one_mug_found_for_two_lost_look_alikes_is_reported_not_guessed(anchoring, maker):
    seen_twice(anchoring, maker, [KITCHEN_MUG, TWIN], 0.0)
    see(anchoring, maker, [], 1.0)  # both gone
    assert {a.state for a in anchoring.anchors} == {AnchorState.MISSING}
    seen_twice(anchoring, maker, [KITCHEN_MUG], WALKED_THERE, camera=False, positions={"blue_mug": LIVING_ROOM})
    result = search_living_room(anchoring, "cup_1", WALKED_THERE + 1.0)
    assert [(e.kind, e.symbol) for e in result.events] == [
        (AnchorEventKind.AMBIGUOUS, "cup_1"), (AnchorEventKind.AMBIGUOUS, "cup_2")]
    assert anchoring.get("cup_1").indistinguishable_from == ("cup_2", "cup_3")
    assert anchoring.get("cup_3").state is AnchorState.CONFIRMED and len(anchoring) == 3


def test_a_newcomer_of_another_look_beside_a_missing_anchor_is_not_it(anchoring, maker):
    seen_twice(anchoring, maker, [KITCHEN_MUG], 0.0)
    see(anchoring, maker, [], 1.0)
    green_in_place = SceneObject("green_mug", "cup", KITCHEN_MUG.position)
    seen_twice(anchoring, maker, [green_in_place], 2.0)
    assert {a.symbol: a.state for a in anchoring.anchors} == {
        "cup_1": AnchorState.MISSING, "cup_2": AnchorState.CONFIRMED}


def test_a_search_under_way_recognises_the_object_when_it_is_anchored_anew(anchoring, maker):
    """The search was announced before the moved mug was seen: it was anchored anew (the camera
    saw it from afar, outside the searched disc's reach of the matching gate); the confirmation
    itself brings it into question, and the search finds it: recorded at once (the camera had not
    watched there), taken when the search concludes."""
    seen_twice(anchoring, maker, [KITCHEN_MUG, GREEN_MUG], 0.0)
    mug, green = symbol_at(anchoring, KITCHEN_MUG), symbol_at(anchoring, GREEN_MUG)
    see(anchoring, maker, [GREEN_MUG], 1.0)
    assert anchoring.get(mug).state is AnchorState.MISSING
    assert search_living_room(anchoring, mug, 1.5).events == ()  # nothing new yet: the green one is older
    moved = np.array((1.5, 8.0, 0.8))  # 2 m from the centre: beyond the disc, within its tolerance
    for frame in range(2):
        # 6 s: late enough to have been carried 7.7 m (carry_speed), early enough for the matching
        # gate, which widens while an anchor is unseen, not to reach it from the disc.
        result = see(anchoring, maker, [KITCHEN_MUG], 6.0 + frame * FRAME, camera=False,
                     positions={"blue_mug": moved})
        assert not [e for e in result.events if e.kind is AnchorEventKind.FORGOTTEN], "merged before concluding"
    newcomer = min(anchoring.anchors, key=lambda anchor: np.linalg.norm(anchor.position - moved)).symbol
    assert newcomer not in (mug, green) and anchoring.get(newcomer).state is AnchorState.CONFIRMED
    assert recorded(anchoring, mug) == (AnchorState.MISSING, newcomer)
    result = anchoring.conclude_search(mug)
    assert kinds(result) == [(AnchorEventKind.FORGOTTEN, newcomer), (AnchorEventKind.CONFIRMED, mug)]
    assert result.events[0].details["reason"].endswith(f"it is {mug}")
    cup = anchoring.get(mug)
    assert cup.state is AnchorState.CONFIRMED and cup.expectation is None
    np.testing.assert_allclose(cup.position, moved, atol=0.05)
    assert anchoring.get(green).state is AnchorState.CONFIRMED and len(anchoring) == 2


def lost_rival_and_newcomer(maker, rival_likeness_offset: float):
    """The red mug lost in the kitchen and sought in the living room; a green mug of the living room
    MISSING there for a moment; a newcomer beside the green mug that looks like it (or, with a
    ``rival_likeness_offset``, less so) and somewhat like the red mug."""
    from merlin2_sailor.anchoring.anchor import Anchor
    from merlin2_sailor.anchoring.anchor_index import AnchorIndex
    from merlin2_sailor.anchoring.fusion import FusionConfig
    fusion = FusionConfig()
    red = np.zeros(maker.dimension, dtype=np.float32)
    red[0] = 1.0
    between = red.copy()
    between[1] = 0.65  # its look scores about 0.6 against the red mug's (the rules times likeness)
    between /= np.linalg.norm(between)
    green = between.copy()
    green[2] = rival_likeness_offset
    green /= np.linalg.norm(green)

    def anchor(symbol, item, stamp, look, position=None):
        made = Anchor.from_percept(symbol, dataclasses.replace(maker.percept(item, stamp, position=position),
                                                               embedding=look), look, fusion)
        made.absorb(dataclasses.replace(maker.percept(item, stamp + FRAME, position=position), embedding=look), look,
                    fusion)
        made.state = AnchorState.CONFIRMED
        return made

    lost = anchor("cup_1", KITCHEN_MUG, 0.0, red)
    rival = anchor("cup_2", GREEN_MUG, 0.0, green)
    for missing in (lost, rival):
        missing.state, missing.lost_after, missing.missing_since = AnchorState.MISSING, missing.last_seen, 2.0
    newcomer = anchor("cup_3", GREEN_MUG, WALKED_THERE, between, position=(2.07, 6.2, 0.8))
    index = AnchorIndex()
    for item in (lost, rival, newcomer):
        index.add(item)
    return lost, rival, newcomer, index


@pytest.mark.parametrize(("rival_offset", "outcome"), [(0.0, None), (0.55, "undecided")],
                         ids=["clearly the rival's", "alike"])
def test_a_newcomer_clearly_another_lost_anchors_is_not_called_ambiguous(maker, rival_offset, outcome):
    """A search for the red mug sees a newcomer that scores just over the threshold against it, and
    near 1 against the green mug that went missing beside it a moment ago (a second anchor of the
    green mug): that newcomer is the green mug's business, and nothing is decided or called
    ambiguous for the red one (test_mission_end_to_end, network, 5 December 2026: "cannot be told
    apart" ended the mission). Where the green mug scores no better than the red one, it stays
    undecided."""
    from merlin2_sailor.anchoring.identity_repair import IdentityRepair, RepairConfig, Undecided
    lost, rival, newcomer, index = lost_rival_and_newcomer(maker, rival_offset)
    repair = IdentityRepair(AppearanceRules(), 0.5, RepairConfig(), search_tolerance=0.5)
    search = Expectation.at(LIVING_ROOM, WALKED_THERE + 1.0, "living_room", "find", radius=1.5)
    scores = [float(identity_scores(AppearanceRules(), [newcomer], sought, SearchedDisc(LIVING_ROOM, 2.0))[0])
              for sought in (lost, rival)]
    assert 0.5 <= scores[0] < 0.75, scores  # the red mug's candidate, barely
    decision = repair.decide_search(lost, search, index)
    if outcome is None:
        assert scores[1] > scores[0] + 0.15, scores
        assert decision is None
    else:
        assert abs(scores[1] - scores[0]) < 0.15, scores
        assert isinstance(decision, Undecided) and decision.found == (newcomer,)


def test_an_ambiguity_naming_an_anchor_since_forgotten_is_withdrawn(maker):
    """The red mug could not be told from two newcomers; one of them proved a second anchor of the
    other's object and was forgotten: what made the case undecided is gone, so the red mug is no
    longer reported as one that cannot be told apart (the next judgement decides afresh)."""
    from merlin2_sailor.anchoring.merge import withdraw_stale_ambiguities
    lost, rival, newcomer, index = lost_rival_and_newcomer(maker, 0.0)
    lost.indistinguishable_from = (rival.symbol, newcomer.symbol)
    withdraw_stale_ambiguities(index)
    assert lost.indistinguishable_from == (rival.symbol, newcomer.symbol)  # all still anchors: it stands
    index.remove(newcomer.symbol)
    withdraw_stale_ambiguities(index)
    assert lost.indistinguishable_from == ()


@pytest.mark.parametrize(("metres", "seconds", "carried"), [
    (5.5, 0.73, False),  # the television: last seen in the living room, the bedroom's seen 0.73 s later
    (5.5, 2.0, False),
    (5.5, 5.0, True),
    (3.0, 1.0, False),
    (3.0, 2.5, True),
    (8.0, 4.0, False),
    (8.0, 6.0, True),
])
def test_a_look_alike_seen_too_soon_too_far_away_is_not_the_lost_object(maker, metres, seconds, carried):
    """A search takes a newcomer that looks the same for the lost object only if someone could have
    carried it there in the time between the lost anchor's last sighting and the newcomer's first
    (probe scenario, network, seed 0, 5 December 2026: a television taken out of the house was
    reported found as the bedroom's, of one make, first seen 5.5 m away 0.73 s later). The bedroom
    was never watched: a newcomer that could have been carried there is recorded as found by look
    alone and taken when the search concludes; one that could not is neither."""
    from merlin2_sailor.anchoring.identity_repair import RepairConfig
    lost_place = np.array(KITCHEN_MUG.position)
    elsewhere = lost_place + (0.0, metres, 0.0)
    look_alike = SceneObject("look_alike", "cup", tuple(elsewhere), looks_like="blue_mug")

    def search_after(carry_speed):
        lifecycle = LifecycleConfig(confirm_after=2, missed_frames_to_missing=1, forget_after=600.0)
        anchoring = Anchoring(AnchoringConfig(lifecycle=lifecycle, repair=RepairConfig(carry_speed=carry_speed)),
                              AppearanceRules())
        seen_twice(anchoring, maker, [KITCHEN_MUG], 0.0)
        last_sighting = anchoring.get("cup_1").last_seen
        see(anchoring, maker, [], last_sighting + 0.5)  # the kitchen camera: gone
        assert anchoring.get("cup_1").state is AnchorState.MISSING
        seen_twice(anchoring, maker, [look_alike], last_sighting + seconds, camera=False)
        assert anchoring.get("cup_2").state is AnchorState.CONFIRMED
        disc = Expectation.at(elsewhere, last_sighting + seconds + 1.0, "bedroom", "find", radius=1.0)
        searched = kinds(anchoring.expect("cup_1", disc))
        return searched, recorded(anchoring, "cup_1"), concluded(anchoring, "cup_1")

    merged = [(AnchorEventKind.FORGOTTEN, "cup_2"), (AnchorEventKind.CONFIRMED, "cup_1")]
    taken = ([], (AnchorState.MISSING, "cup_2"), merged)  # recorded by the search, taken when it concludes
    nothing = ([], (AnchorState.MISSING, ""), [])
    assert search_after(RepairConfig().carry_speed) == (taken if carried else nothing)
    assert search_after(0.0) == taken  # without the bound, the look decides alone: the failure fixed


@pytest.mark.parametrize("value", [-0.5, float("nan"), float("inf")])
def test_a_bad_carry_speed_is_refused(value):
    from merlin2_sailor.anchoring.identity_repair import RepairConfig
    from merlin2_sailor.errors import ConfigurationError
    with pytest.raises(ConfigurationError, match="carry_speed"):
        RepairConfig(carry_speed=value)


@pytest.mark.parametrize(("view", "found"), [("cut by the image's edge", "cup_2"), ("whole", "")])
def test_a_part_seen_at_the_old_place_after_the_object_was_anchored_elsewhere_does_not_rule_it_out(
        anchoring, maker, view, found):
    """The mug, carried to the living room, is anchored anew there; 2 s later, the robot's camera,
    back in the kitchen, sees a mug's box at its old place, cut by the image's edge: it keeps the
    kitchen anchor alive but does not place it (:meth:`.Anchor.absorb`), and the anchor is lost
    at the next frame. Its loss is dated from the sighting that last placed it, so the living
    room's newcomer, born after that, may still be it, and the search finds it (scenario suite,
    `large_object_wheeled_away`, network, seed 1, 6 December 2026: the bicycle's anchor took such a
    view 19 s after the wheeled bicycle was anchored anew; the two "stood together", and the
    search found nothing). A whole view there is the mug seen in both places at once, as before:
    the newcomer is another mug."""
    from .test_anchoring_partial_views import EDGE_BOX, MIDDLE_BOX
    seen_twice(anchoring, maker, [KITCHEN_MUG], 0.0)
    seen_twice(anchoring, maker, [KITCHEN_MUG], WALKED_THERE, camera=False, positions={"blue_mug": LIVING_ROOM})
    assert [anchor.state for anchor in anchoring.anchors] == [AnchorState.CONFIRMED] * 2
    box = EDGE_BOX if view != "whole" else MIDDLE_BOX
    part = dataclasses.replace(maker.percept(KITCHEN_MUG, WALKED_THERE + 2.0), box=box)
    anchoring.process([part], camera_view(), WALKED_THERE + 2.0)
    assert anchoring.get("cup_1").last_seen == WALKED_THERE + 2.0 and len(anchoring) == 2  # it took the view
    see(anchoring, maker, [], WALKED_THERE + 2.5)
    lost = anchoring.get("cup_1")
    assert lost.state is AnchorState.MISSING
    assert lost.lost_after == (FRAME if view != "whole" else WALKED_THERE + 2.0)
    from merlin2_sailor.anchoring.snapshot import anchor_from_dict, anchor_to_dict
    assert anchor_from_dict(anchor_to_dict(lost)).last_placed == lost.last_placed  # kept over a restart
    assert search_living_room(anchoring, "cup_1", WALKED_THERE + 3.0).events == ()
    assert recorded(anchoring, "cup_1") == (AnchorState.MISSING, found)
    assert concluded(anchoring, "cup_1") == (
        [(AnchorEventKind.FORGOTTEN, "cup_2"), (AnchorEventKind.CONFIRMED, "cup_1")] if found else [])
    if found:  # placed, now, where the newcomer saw it
        assert anchoring.get("cup_1").last_placed == pytest.approx(WALKED_THERE + FRAME)


def test_the_bound_measures_from_where_the_lost_object_was_last_seen_before_it_went_missing(maker):
    """A sighting while missing (too few to bring the anchor back; a false detection on the way,
    probe scenario, seed 8) moves the anchor's perceived position, not the place its object was
    last seen: the look-alike first seen 2 s after that, 5.5 m from it but 3 m from the false
    sighting, is still too far to have been carried there."""
    from merlin2_sailor.anchoring.anchor_index import AnchorIndex
    from merlin2_sailor.anchoring.identity_repair import IdentityRepair, RepairConfig
    from merlin2_sailor.anchoring.snapshot import anchor_from_dict, anchor_to_dict
    lifecycle = LifecycleConfig(confirm_after=2, missed_frames_to_missing=1, forget_after=600.0)
    anchoring = Anchoring(AnchoringConfig(lifecycle=lifecycle), AppearanceRules())
    seen_twice(anchoring, maker, [KITCHEN_MUG], 0.0)
    see(anchoring, maker, [], 0.5)
    lost = anchoring.get("cup_1")
    assert lost.state is AnchorState.MISSING
    last_place = np.array(KITCHEN_MUG.position)
    np.testing.assert_allclose(lost.lost_at, lost.perceived_position)
    restored = anchor_from_dict(anchor_to_dict(lost))
    np.testing.assert_allclose(restored.lost_at, lost.lost_at)
    lost.perceived_position = last_place + (0.0, 2.5, 0.0)  # what a sighting while missing leaves
    look_alike = SceneObject("look_alike", "cup", tuple(last_place + (0.0, 5.5, 0.0)), looks_like="blue_mug")
    seen_twice(anchoring, maker, [look_alike], lost.lost_after + 2.0, camera=False)
    candidate = anchoring.get("cup_2")
    index = AnchorIndex()
    for anchor in (lost, candidate):
        index.add(anchor)
    search = Expectation.at(candidate.position, lost.lost_after + 3.0, "bedroom", "find", radius=1.0)
    repair = IdentityRepair(AppearanceRules(), 0.5, RepairConfig(), search_tolerance=0.5)
    assert repair.decide_search(lost, search, index) is None
    lost.lost_at = None  # measured from the perceived position instead, it would be taken
    assert repair.decide_search(lost, search, index).merged is candidate


@pytest.mark.parametrize("far_views", [2, 3, 5])
def test_a_newcomer_first_seen_from_afar_is_judged_by_its_views_comparable_to_the_lost_ones(maker, far_views):
    """The lost mug, seen close in the kitchen, is sought in the living room, where the robot saw it
    first from across the room and then close: its new anchor's gallery keeps both. The far views
    (a fifth of the size, their crops blurred: another look to the matcher) say little and are left
    out; the close view, as the lost mug looks, decides (real-MERLIN2 mission test, CI, 5 December
    2026: the moved mug's new anchor scored 0.75 by its close view, 0.48 over all four, and was
    never found). A newcomer with only far views is still judged by them: it is not found on a
    view nobody could tell."""
    from merlin2_sailor.anchoring.anchor import Anchor
    from merlin2_sailor.anchoring.anchor_index import AnchorIndex
    from merlin2_sailor.anchoring.fusion import FusionConfig
    from merlin2_sailor.anchoring.gallery import to_bfloat16_bits
    from merlin2_sailor.anchoring.identity_repair import IdentityRepair, Merge, RepairConfig
    fusion = FusionConfig()
    look = maker.appearance(KITCHEN_MUG.identity)
    blurred = look + np.random.default_rng(far_views).normal(scale=1.0, size=look.shape)
    blurred /= np.linalg.norm(blurred)

    def anchor(symbol, item, stamp, views, sizes, position=None):
        made = Anchor.from_percept(symbol, maker.percept(item, stamp, position=position), None, fusion)
        made.gallery = to_bfloat16_bits(np.asarray(views, dtype=np.float32))
        made.gallery_scales = np.asarray(sizes, dtype=np.float32)
        made.state = AnchorState.CONFIRMED
        return made

    lost = anchor("cup_1", KITCHEN_MUG, 0.0, [look, look], [50.0, 55.0])
    lost.state, lost.lost_after, lost.missing_since = AnchorState.MISSING, lost.last_seen, 2.0
    lost.lost_at = lost.position.copy()
    moved = SceneObject("blue_mug_moved", "cup", (1.6, 6.1, 0.8), looks_like="blue_mug")
    views, sizes = [blurred] * far_views, [10.0 + k for k in range(far_views)]
    index = AnchorIndex()
    for item in (lost, anchor("cup_2", moved, WALKED_THERE, [*views, look], [*sizes, 60.0])):
        index.add(item)
    search = Expectation.at(LIVING_ROOM, WALKED_THERE + 1.0, "living_room", "find", radius=1.5)

    def decide(far_view_ratio):
        return IdentityRepair(AppearanceRules(), 0.5, RepairConfig(), search_tolerance=0.5,
                              far_view_ratio=far_view_ratio).decide_search(lost, search, index)

    assert isinstance(decide(0.5), Merge)
    assert decide(0.0) is None  # every view counted: the far ones outvote the close one (the failure)
    only_far = anchor("cup_2", moved, WALKED_THERE, views, sizes)
    index.remove("cup_2")
    index.add(only_far)
    assert decide(0.5) is None


def test_a_tentative_anchor_confirmed_long_after_its_first_sighting_may_be_the_lost_object(anchoring, maker):
    """A glimpse of a mug in the living room leaves a tentative anchor while the blue mug is still in
    the kitchen; a minute later the blue mug, moved there, confirms that anchor. Born again with its
    count, it may be the blue mug (`moved_while_its_twin_is_watched`, network, seed 2, 5 December
    2026: it could not, and the search gave up): the search records it, and takes it when it
    concludes."""
    seen_twice(anchoring, maker, [KITCHEN_MUG], 0.0)
    glimpse = SceneObject("glimpse", "cup", tuple(LIVING_ROOM), looks_like="blue_mug")
    see(anchoring, maker, [KITCHEN_MUG, glimpse], 2 * FRAME, camera=False)
    see(anchoring, maker, [KITCHEN_MUG], 3 * FRAME, camera=False)
    assert anchoring.get("cup_2").state is AnchorState.TENTATIVE
    see(anchoring, maker, [], 1.0)  # the kitchen seen empty
    assert anchoring.get("cup_1").state is AnchorState.MISSING
    seen_twice(anchoring, maker, [KITCHEN_MUG], 60.0, camera=False, positions={"blue_mug": LIVING_ROOM})
    assert anchoring.get("cup_2").state is AnchorState.CONFIRMED and anchoring.get("cup_2").first_seen == 60.0
    assert search_living_room(anchoring, "cup_1", 61.0).events == ()
    assert recorded(anchoring, "cup_1") == (AnchorState.MISSING, "cup_2")
    assert concluded(anchoring, "cup_1") == [(AnchorEventKind.FORGOTTEN, "cup_2"), (AnchorEventKind.CONFIRMED, "cup_1")]


def test_a_search_for_an_anchor_perception_has_confirmed_leaves_it_where_it_was_seen(anchoring, maker):
    """A find visits the stop nearest where the sought object was just seen and announces a search
    there; the anchor must stay where perception put it, not move to the stop's disc."""
    seen_twice(anchoring, maker, [KITCHEN_MUG], 0.0)
    before = anchoring.get("cup_1").position.copy()
    result = search_living_room(anchoring, "cup_1", 1.0)
    assert result.events == ()
    anchor = anchoring.get("cup_1")
    assert anchor.state is AnchorState.CONFIRMED and anchor.expectation is None
    np.testing.assert_allclose(anchor.position, before)


def test_a_case_that_rests_on_an_anchor_merged_earlier_in_the_frame_is_not_carried_out() -> None:
    """A frame's decisions are made first and carried out in turn, each only while every anchor it
    involves is still anchored: an undecided case involves its lost and found anchors and the twins
    it rests on, so "cup_2 looks like cup_1 but so does cup_3" is dropped once cup_3 was merged
    into cup_2 as the same mug reappearing (CI, 7 December 2026: the search for the moved mug
    stayed undecided for good)."""
    maker = PerceptMaker(seed=4)
    lost, found, twin, other = (
        Anchor.from_percept(symbol, maker.percept(SceneObject(symbol, "cup", (x, 0.0, 0.8)), 0.0), None, FusionConfig())
        for symbol, x in (("cup_1", 0.0), ("cup_2", 2.0), ("cup_3", 2.05), ("cup_4", 4.0)))
    case = Undecided((lost,), (found,), (0.8,), "cup_2 looks like cup_1 but so does cup_3", also=(twin,))
    assert {anchor.symbol for anchor in involved(case)} == {"cup_1", "cup_2", "cup_3"}
    plain = Undecided((lost,), (found, other), (0.8, 0.8), "cup_1 may be any of cup_2, cup_4")
    assert {anchor.symbol for anchor in involved(plain)} == {"cup_1", "cup_2", "cup_4"}
