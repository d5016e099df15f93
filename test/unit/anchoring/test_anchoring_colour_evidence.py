"""Colour rules a merge out only on evidence: the colours of the objects' own pixels, with either matcher.

The matcher here is the rules (the default), which have no appearance of their own: before
colour evidence they took a mug of another colour, found where a lost mug was sought, for it.
Colours are synthetic histograms shaped like the demo's mugs (mostly shared coffee and shadow,
a small share of the mug's own colour), with per-view noise.
"""

from __future__ import annotations

import dataclasses
import itertools
import json
import math
import re

import numpy as np
import pytest

from merlin2_sailor.anchoring import AnchorEventKind, Anchoring, AnchoringConfig, AnchorState, Expectation
from merlin2_sailor.anchoring.anchor import Anchor
from merlin2_sailor.anchoring.anchor_view import AnchorView
from merlin2_sailor.anchoring.colour_evidence import (
    ColourBySize,
    ColourEvidenceConfig,
    ColourModel,
    anchor_colour_gap,
    anchor_colours_differ,
    colour_difference,
    colour_windows,
    colours_agree,
    colours_differ,
    combined,
    combined_by_size,
    view_differs,
    view_key_from_text,
    view_key_order,
    view_key_text,
    with_sized_view,
)
from merlin2_sailor.anchoring.lifecycle import LifecycleConfig
from merlin2_sailor.anchoring.rule_matcher import RuleMatcher
from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.errors import ConfigurationError, InvalidInputError
from merlin2_sailor.perception.colour_histogram import COLOUR_BINS, HUE_BINS

from .anchoring_scenes import PerceptMaker, SceneObject, camera_view, mug_colour

FRAME = 1.0 / 15.0
RED, GREEN, BLUE = 17, 6, 11
KITCHEN = (2.0, 0.3, 0.8)
LIVING_ROOM = np.array((1.5, 6.0, 0.8))


def noisy_views(histogram: np.ndarray, count: int, rng: np.random.Generator, noise: float = 0.01) -> list[np.ndarray]:
    views = []
    for _ in range(count):
        view = np.clip(histogram + rng.normal(scale=noise, size=COLOUR_BINS), 0.0, None)
        views.append(view / view.sum())
    return views


def model_of(views: list[np.ndarray]) -> ColourModel:
    model = ColourModel.of(views[0])
    for view in views[1:]:
        model.add(view)
    return model


# --- the model and the test ------------------------------------------------------------------


def test_windows_sum_each_hue_with_its_neighbours_around_the_circle() -> None:
    histogram = np.zeros(COLOUR_BINS)
    histogram[0] = 1.0
    windows = colour_windows(histogram)
    assert windows[[HUE_BINS - 1, 0, 1]].tolist() == [1.0, 1.0, 1.0] and windows.sum() == 3.0
    with pytest.raises(InvalidInputError, match="21 values"):
        colour_windows(np.ones(5))


def test_merging_two_models_equals_one_model_of_every_view() -> None:
    rng = np.random.default_rng(3)
    views = noisy_views(mug_colour(RED), 9, rng, noise=0.03)
    first, second, whole = model_of(views[:4]), model_of(views[4:]), model_of(views)
    merged = combined(first, second)
    assert merged.views == 9
    np.testing.assert_allclose(merged.mean, whole.mean)
    np.testing.assert_allclose(merged.variance, whole.variance)
    np.testing.assert_allclose(merged.variance, np.var([colour_windows(v) for v in views], axis=0, ddof=1))
    alone = combined(None, first)
    assert alone is not first and alone.views == 4  # a copy: the merged anchor's model is not shared


@pytest.mark.parametrize(("own", "other"), list(itertools.permutations([4, 7, 10, 13, 16], 2)))
def test_mugs_of_two_colours_differ_and_views_of_one_mug_never_do(own: int, other: int) -> None:
    rng = np.random.default_rng(own * 100 + other)
    config = ColourEvidenceConfig()
    share = rng.uniform(0.12, 0.3)
    mine, theirs = mug_colour(own, share), mug_colour(other, share)
    assert colours_differ(model_of(noisy_views(mine, 4, rng)), model_of(noisy_views(theirs, 5, rng)), config)
    assert not colours_differ(model_of(noisy_views(mine, 4, rng)), model_of(noisy_views(mine, 6, rng)), config)


@pytest.mark.parametrize("hue", [4, 9, 13])
def test_a_hue_sliding_into_the_next_bin_is_not_another_colour(hue: int) -> None:
    """One colour seen under another light: part of its pixels one bin over."""
    rng = np.random.default_rng(hue)
    shifted = 0.5 * (mug_colour(hue, 0.2) + mug_colour(hue + 1, 0.2))
    assert not colours_differ(model_of(noisy_views(mug_colour(hue, 0.2), 5, rng)),
                              model_of(noisy_views(shifted, 5, rng)), ColourEvidenceConfig())


def test_no_evidence_until_one_side_knows_its_colour_nor_from_no_colour_or_within_the_noise() -> None:
    rng = np.random.default_rng(5)
    config = ColourEvidenceConfig()
    red, green = model_of(noisy_views(mug_colour(RED), 2, rng)), model_of(noisy_views(mug_colour(GREEN), 2, rng))
    assert not colours_differ(red, green, config)  # two views each: nobody knows a colour yet
    green = model_of(noisy_views(mug_colour(GREEN), 8, rng))
    # A newcomer of two views against a known anchor: judged by the known anchor's spread.
    assert colour_difference(red, green, config) == pytest.approx(0.15, abs=0.03)
    assert view_differs(green, noisy_views(mug_colour(RED), 1, rng)[0], config)
    assert not view_differs(green, noisy_views(mug_colour(GREEN), 1, rng)[0], config)
    assert not view_differs(green, None, config)
    assert not colours_differ(None, green, config)
    assert not colours_differ(red, green, dataclasses.replace(config, minimum_views=0))
    # Views that vary as much as the difference are no evidence of it.
    jumpy = model_of(noisy_views(mug_colour(RED), 8, rng, noise=0.08))
    assert not colours_differ(jumpy, green, config)
    assert not view_differs(jumpy, noisy_views(mug_colour(GREEN), 1, rng)[0], config)


def test_configuration_is_checked() -> None:
    with pytest.raises(ConfigurationError, match="colour_minimum_views"):
        ColourEvidenceConfig(minimum_views=-1)
    with pytest.raises(ConfigurationError, match="colour_minimum_difference"):
        ColourEvidenceConfig(minimum_difference=1.0)
    with pytest.raises(ConfigurationError, match="colour_noise_factor"):
        ColourEvidenceConfig(noise_factor=float("nan"))
    with pytest.raises(ConfigurationError, match="colour_absence"):
        ColourEvidenceConfig(absence=-1.0)
    with pytest.raises(ConfigurationError, match="colour_comparable_size"):
        ColourEvidenceConfig(comparable_size=0.5)
    with pytest.raises(ConfigurationError, match="colour_place_radius"):
        ColourEvidenceConfig(place_radius=0.0)
    with pytest.raises(ConfigurationError, match="colour_second_view_after"):
        ColourEvidenceConfig(second_view_after=-0.1)


# --- in the anchoring core, with the rules ---------------------------------------------------


def rules(colour: ColourEvidenceConfig | None = None) -> Anchoring:
    lifecycle = LifecycleConfig(confirm_after=2, missed_frames_to_missing=1, forget_after=600.0)
    return Anchoring(AnchoringConfig(lifecycle=lifecycle, colour=colour or ColourEvidenceConfig()), RuleMatcher())


def see(anchoring, maker, items, start, frames=4, camera=True, positions=None):
    result = None
    for frame in range(frames):
        stamp = start + frame * FRAME
        percepts = [maker.percept(item, stamp, position=(positions or {}).get(item.identity)) for item in items]
        result = anchoring.process(percepts, camera_view() if camera else None, stamp)
    return result


#: Frames (at 15 Hz) that span colour's ``second_view_after``: a first view of another colour only
#: raises a suspicion, a second one this long after rules the anchor out.
SUSPICION_FRAMES = 1 + math.ceil(ColourEvidenceConfig().second_view_after / FRAME)


def acquired_events(anchoring, maker, items, start):
    """The ACQUIRED events of the frames that span a suspicion and its confirmation."""
    events = []
    for frame in range(SUSPICION_FRAMES):
        stamp = start + frame * FRAME
        result = anchoring.process([maker.percept(item, stamp) for item in items], camera_view(), stamp)
        events += [event for event in result.events if event.kind is AnchorEventKind.ACQUIRED]
    return events


#: When the robot, having left the kitchen at 1 s, first sees the living room (5.7 m away): late
#: enough for someone to have carried the mug there (identity_repair's ``carry_speed``).
WALKED_THERE = 10.0


def search(anchoring, symbol, stamp):
    return anchoring.expect(symbol, Expectation.at(LIVING_ROOM, stamp, "living_room", "find", radius=1.5))


def kinds(result):
    return [(event.kind, event.symbol) for event in result.events]


def recorded(anchoring, symbol):
    """The sought anchor's state and the candidate its search found by look alone ("": none): where
    the camera had never watched before a candidate was seen, the search only records it."""
    sought = anchoring.get(symbol)
    return sought.state, sought.found_by_look_alone


def concluded(anchoring, symbol):
    """The search for ``symbol`` has looked everywhere: what concluding it does, as (kind, symbol)."""
    return kinds(anchoring.conclude_search(symbol))


def lose_and_search(anchoring, maker, sought: SceneObject, found: SceneObject, found_at=None):
    """The sought mug is seen in the kitchen, then not; ``found`` is seen in the living room (not
    by the kitchen camera), once the robot has walked there; then a search for the sought one
    looks there. The living room was never watched: a find there is only recorded until the
    search concludes (:func:`recorded`, :func:`concluded`)."""
    see(anchoring, maker, [sought], 0.0)
    see(anchoring, maker, [], 1.0, frames=1)
    assert anchoring.get("cup_1").state is AnchorState.MISSING
    see(anchoring, maker, [found], WALKED_THERE, camera=False, positions={found.identity: found_at})
    return search(anchoring, "cup_1", WALKED_THERE + 1.0)


@pytest.mark.parametrize(("sought_hue", "found_hue"), [(RED, GREEN), (GREEN, RED), (BLUE, RED), (0, 9), (14, 5)])
def test_a_removed_mug_is_never_found_as_a_mug_of_another_colour(sought_hue: int, found_hue: int) -> None:
    sought = SceneObject("sought", "cup", KITCHEN, colour=mug_colour(sought_hue))
    other = SceneObject("other", "cup", tuple(LIVING_ROOM), colour=mug_colour(found_hue, 0.2))
    anchoring = rules()
    result = lose_and_search(anchoring, maker := PerceptMaker(seed=sought_hue), sought, other)
    assert result.events == ()
    assert recorded(anchoring, "cup_1") == (AnchorState.MISSING, "")  # not even found by look alone
    assert concluded(anchoring, "cup_1") == []  # so concluding the search takes nothing
    assert anchoring.get("cup_1").state is AnchorState.MISSING
    assert anchoring.get("cup_2").state is AnchorState.CONFIRMED
    # Without colour evidence the rules take the other mug for the sought one: the failure fixed.
    blind = rules(ColourEvidenceConfig(minimum_views=0))
    assert lose_and_search(blind, maker, sought, other).events == ()
    assert recorded(blind, "cup_1") == (AnchorState.MISSING, "cup_2")
    assert (AnchorEventKind.FORGOTTEN, "cup_2") in concluded(blind, "cup_1")


@pytest.mark.parametrize("hue", [RED, GREEN, 3])
def test_a_moved_mug_of_the_same_colour_is_still_found(hue: int) -> None:
    sought = SceneObject("sought", "cup", KITCHEN, colour=mug_colour(hue))
    anchoring = rules()
    result = lose_and_search(anchoring, PerceptMaker(seed=hue), sought, sought, found_at=LIVING_ROOM)
    assert result.events == ()
    assert recorded(anchoring, "cup_1") == (AnchorState.MISSING, "cup_2")
    assert concluded(anchoring, "cup_1") == [(AnchorEventKind.FORGOTTEN, "cup_2"), (AnchorEventKind.CONFIRMED, "cup_1")]
    assert anchoring.get("cup_1").colour.views == 8  # both anchors' views, one model


def test_the_sought_mug_is_told_from_mugs_of_other_colours_found_beside_it() -> None:
    """The demo's failure: the red mug found beside two green ones; the rules alone cannot tell
    which it is (undecided, and concluding the search takes none), the colours can (the search
    records the red one, and takes it when it concludes)."""
    red = SceneObject("red", "cup", KITCHEN, colour=mug_colour(RED))
    greens = [SceneObject(f"green_{n}", "cup", (1.5 + 0.4 * n, 6.3, 0.8), colour=mug_colour(GREEN)) for n in range(2)]
    moved = SceneObject("red", "cup", (1.7, 5.7, 0.8), colour=mug_colour(RED))
    outcomes = {}
    for name, colour in (("colour", None), ("blind", ColourEvidenceConfig(minimum_views=0))):
        anchoring = rules(colour)
        maker = PerceptMaker(seed=9)
        see(anchoring, maker, [red], 0.0)
        see(anchoring, maker, [], 1.0, frames=1)
        see(anchoring, maker, [moved, *greens], WALKED_THERE, camera=False)
        # Symbols of one frame's new anchors follow their places: find the moved red mug's.
        moved_symbol = next(anchor.symbol for anchor in anchoring.anchors if anchor.symbol != "cup_1"
                            and np.linalg.norm(anchor.position[:2] - np.array(moved.position[:2])) < 0.2)
        searched = kinds(search(anchoring, "cup_1", WALKED_THERE + 1.0))
        outcomes[name] = searched, recorded(anchoring, "cup_1"), concluded(anchoring, "cup_1")
    assert outcomes["colour"] == ([], (AnchorState.MISSING, moved_symbol),
                                  [(AnchorEventKind.FORGOTTEN, moved_symbol), (AnchorEventKind.CONFIRMED, "cup_1")])
    assert outcomes["blind"] == ([(AnchorEventKind.AMBIGUOUS, "cup_1")], (AnchorState.MISSING, ""), [])


@pytest.mark.parametrize(("own", "other"), [(RED, GREEN), (GREEN, BLUE), (BLUE, 3)])
def test_a_mug_of_another_colour_put_in_the_place_of_one_unseen_for_a_while_is_not_it(own: int, other: int) -> None:
    """The swap: while the camera looked away the red mug was replaced by a green one. The rules
    score place and time only, and would reacquire the red mug's anchor with the green mug."""
    red = SceneObject("red", "cup", KITCHEN, colour=mug_colour(own))
    green_in_place = SceneObject("green", "cup", KITCHEN, colour=mug_colour(other))
    anchoring, maker = rules(), PerceptMaker(seed=own)
    see(anchoring, maker, [red], 0.0)
    result = see(anchoring, maker, [green_in_place], 60.0, frames=SUSPICION_FRAMES + 3)
    assert result.percept_symbols == ("cup_2",)
    assert {anchor.symbol: anchor.state for anchor in anchoring.anchors} == {
        "cup_1": AnchorState.MISSING, "cup_2": AnchorState.CONFIRMED}
    blind = rules(ColourEvidenceConfig(minimum_views=0))
    see(blind, maker, [red], 0.0)
    assert see(blind, maker, [green_in_place], 60.0).percept_symbols == ("cup_1",)


def test_one_view_rules_out_only_an_anchor_unseen_for_a_while_and_only_when_whole() -> None:
    red = SceneObject("red", "cup", KITCHEN, colour=mug_colour(RED))
    green_in_place = SceneObject("green", "cup", KITCHEN, colour=mug_colour(GREEN))
    anchoring, maker = rules(), PerceptMaker(seed=8)
    see(anchoring, maker, [red], 0.0)
    # Nobody swaps a mug between two looks a second apart: a view then is no evidence alone.
    assert see(anchoring, maker, [green_in_place], 1.0, frames=1).percept_symbols == ("cup_1",)
    # The same mug back after a minute is the same anchor.
    assert see(anchoring, maker, [red], 60.0).percept_symbols == ("cup_1",)
    # Without a camera view nothing says the view is whole: it is no evidence either.
    percept = maker.percept(green_in_place, 200.0)
    assert anchoring.process([percept], None, 200.0).percept_symbols == ("cup_1",)


def test_partial_views_and_colourless_percepts_do_not_enter_the_model() -> None:
    red = SceneObject("red", "cup", KITCHEN, colour=mug_colour(RED))
    plain = SceneObject("red", "cup", KITCHEN)
    anchoring, maker = rules(), PerceptMaker(seed=2)
    see(anchoring, maker, [red], 0.0, frames=3)
    see(anchoring, maker, [plain], 0.5, frames=2)
    assert anchoring.get("cup_1").colour.views == 3


def test_the_colour_model_survives_a_snapshot_through_json() -> None:
    red = SceneObject("red", "cup", KITCHEN, colour=mug_colour(RED))
    anchoring, maker = rules(), PerceptMaker(seed=1)
    see(anchoring, maker, [red], 0.0)
    restored = rules()
    restored.restore(json.loads(json.dumps(anchoring.snapshot())))
    before, after = anchoring.get("cup_1").colour, restored.get("cup_1").colour
    assert after.views == before.views == 4
    np.testing.assert_allclose(after.mean, before.mean)
    np.testing.assert_allclose(after.squares, before.squares)
    snapshot = anchoring.snapshot()
    snapshot["anchors"][0]["colour"]["mean"] = [0.1, 0.2]
    with pytest.raises(InvalidInputError, match="colour"):
        rules().restore(snapshot)


def test_views_without_colour_do_not_bring_back_an_anchor_a_view_of_another_colour_disputed() -> None:
    """The swap seen from afar first: far views carry no colour, so they reacquire the red mug's
    anchor; the first close view shows green; from then on the red anchor, missing, can be brought
    back only by a view of its own colour, not by more colourless ones."""
    red = SceneObject("red", "cup", KITCHEN, colour=mug_colour(RED))
    green = SceneObject("green", "cup", KITCHEN, colour=mug_colour(GREEN))
    green_far = SceneObject("green", "cup", KITCHEN)
    anchoring, maker = rules(), PerceptMaker(seed=6)
    see(anchoring, maker, [red], 0.0)
    assert see(anchoring, maker, [green_far], 60.0, frames=2).percept_symbols == ("cup_1",)
    assert see(anchoring, maker, [green], 61.0, frames=SUSPICION_FRAMES).percept_symbols == ("cup_2",)
    assert anchoring.get("cup_1").state is AnchorState.MISSING and anchoring.get("cup_1").colour_disputed
    assert see(anchoring, maker, [green_far], 62.0, frames=6).percept_symbols == ("cup_2",)
    assert anchoring.get("cup_1").state is AnchorState.MISSING
    # The red mug put back: a view of its own colour settles the dispute.
    assert see(anchoring, maker, [red], 120.0, frames=6).percept_symbols == ("cup_1",)
    assert not anchoring.get("cup_1").colour_disputed


@pytest.mark.parametrize(("own", "other", "far_frames"), [(RED, GREEN, 2), (GREEN, BLUE, 5), (BLUE, 3, 1)])
def test_colourless_views_before_a_dispute_are_not_reported_as_the_anchors_last_sighting(own, other, far_frames):
    """The swap seen from afar first: the far views of the green mug went to the red mug's anchor;
    once a close view disputes it, the anchor reports its last sighting of its own colour, not
    those, until a view of its own colour comes back."""
    red = SceneObject("red", "cup", KITCHEN, colour=mug_colour(own))
    green = SceneObject("green", "cup", KITCHEN, colour=mug_colour(other))
    green_far = SceneObject("green", "cup", KITCHEN)
    anchoring, maker = rules(), PerceptMaker(seed=own + far_frames)
    see(anchoring, maker, [red], 0.0)
    own_colour_seen = anchoring.get("cup_1").colour_seen
    see(anchoring, maker, [green_far], 60.0, frames=far_frames)
    cup_1 = anchoring.get("cup_1")
    assert cup_1.last_seen == pytest.approx(60.0 + (far_frames - 1) * FRAME)
    assert cup_1.last_sure_sighting == cup_1.last_seen  # nothing has disputed them yet
    see(anchoring, maker, [green], 61.0, frames=SUSPICION_FRAMES)
    assert cup_1.colour_disputed
    assert cup_1.last_seen == pytest.approx(60.0 + (far_frames - 1) * FRAME)  # still when it was matched
    assert cup_1.last_sure_sighting == own_colour_seen
    assert AnchorView.of(cup_1).last_seen == own_colour_seen
    restored = rules()
    restored.restore(json.loads(json.dumps(anchoring.snapshot())))
    assert restored.get("cup_1").last_sure_sighting == own_colour_seen
    # The red mug put back: a view of its own colour ends the doubt.
    see(anchoring, maker, [red], 120.0, frames=6)
    assert not cup_1.colour_disputed and cup_1.doubted_sightings is None
    assert cup_1.last_sure_sighting == cup_1.last_seen == pytest.approx(120.0 + 5 * FRAME)


def test_sightings_after_a_dispute_count_again() -> None:
    """Only the sightings before the dispute are in doubt: one taken later, by a matching that knew
    of it, is reported; an anchor never seen in colour has nothing to fall back on and doubts none."""
    anchor = Anchor("cup_1", "cup", np.zeros(3), np.full(3, 0.1), first_seen=0.0, last_seen=5.0, colour_seen=2.0)
    anchor.dispute_colour()
    assert anchor.doubted_sightings == (2.0, 5.0) and anchor.last_sure_sighting == 2.0
    anchor.last_seen = 7.0
    assert anchor.last_sure_sighting == 7.0
    anchor.dispute_colour()  # disputed again while still seen: what it was given since stays its own
    assert anchor.doubted_sightings == (2.0, 5.0) and anchor.last_sure_sighting == 7.0
    colourless = Anchor("cup_2", "cup", np.zeros(3), np.full(3, 0.1), first_seen=0.0, last_seen=5.0)
    colourless.dispute_colour()
    assert colourless.colour_disputed and colourless.last_sure_sighting == 5.0


def mug_anchor(symbol: str, first_seen: float, last_seen: float, colour_seen: float) -> Anchor:
    return Anchor(symbol, "cup", np.zeros(3), np.full(3, 0.1), first_seen=first_seen, last_seen=last_seen,
                  colour_seen=colour_seen, class_votes={"cup": 1.0})


def test_a_merge_carries_the_latest_colour_check_and_what_it_settled() -> None:
    """A mug found moved: its old anchor, disputed where it stood, takes the newer anchor's views of
    its own colour, so its colour was checked then, the dispute is answered and nothing is in doubt;
    an older view merged in changes none of that."""
    fusion = AnchoringConfig().fusion
    disputed = mug_anchor("cup_1", 0.0, 5.0, colour_seen=2.0)
    disputed.dispute_colour()
    disputed.absorb_anchor(mug_anchor("cup_2", 30.0, 31.0, colour_seen=31.0), fusion)
    assert disputed.colour_seen == 31.0 and not disputed.colour_disputed and disputed.doubted_sightings is None
    assert disputed.last_sure_sighting == 31.0
    kept = mug_anchor("cup_4", 0.0, 5.0, colour_seen=2.0)
    kept.dispute_colour()
    kept.absorb_anchor(mug_anchor("cup_3", 0.5, 1.0, colour_seen=1.0), fusion)
    assert kept.colour_seen == 2.0 and kept.colour_disputed and kept.last_sure_sighting == 2.0


def test_an_anchor_made_because_colour_ruled_out_the_old_one_says_so() -> None:
    red = SceneObject("red", "cup", KITCHEN, colour=mug_colour(RED))
    green = SceneObject("green", "cup", KITCHEN, colour=mug_colour(GREEN))
    anchoring, maker = rules(), PerceptMaker(seed=6)
    see(anchoring, maker, [red], 0.0)
    (acquired,) = acquired_events(anchoring, maker, [green], 61.0)
    assert re.fullmatch(r"cup_1 ruled out by colour \(0\.\d\d in the hue window at \d+ deg: 0\.\d\d in its \d+ views, "
                        r"0\.\d\d in this one\)", acquired.details["nearest_anchor"]), acquired.details
    # With another mug in reach, the account names both: the best score, and the one ruled out.
    blue = SceneObject("blue", "cup", (2.6, 0.3, 0.8), colour=mug_colour(BLUE))
    anchoring, maker = rules(), PerceptMaker(seed=6)
    see(anchoring, maker, [red, blue], 0.0)
    see(anchoring, maker, [blue], 60.0, frames=1)
    (acquired,) = acquired_events(anchoring, maker, [green], 61.0)
    assert acquired.details["nearest_anchor"].startswith("cup_2 scored ")
    assert re.search(r"; cup_1 ruled out by colour \(0\.\d\d in the hue window at \d+ deg: .* in this one\)$",
                     acquired.details["nearest_anchor"]), acquired.details


# --- a single view is held to views of about its size -----------------------------------------


def test_views_are_kept_by_size_and_compared_only_with_views_of_about_that_size() -> None:
    rng = np.random.default_rng(4)
    close, far = noisy_views(mug_colour(RED), 5, rng), noisy_views(mug_colour(RED), 4, rng)
    by_size = None
    for view in close:
        by_size = with_sized_view(by_size, view, 120.0)
    for view in far:
        by_size = with_sized_view(by_size, view, 15.0)
    by_size = with_sized_view(by_size, close[0], 0.0)  # an empty box has no size: left out
    assert sum(model.views for model in by_size.bands.values()) == 9
    assert by_size.comparable(100.0, 2.0).views == 5
    assert by_size.comparable(20.0, 2.0).views == 4
    assert by_size.comparable(45.0, 2.0) is None
    assert by_size.comparable(45.0, 8.0).views == 9
    # Merging two anchors' views keeps them by size, and the whole equals one model of every view.
    other = with_sized_view(None, far[0], 15.0)
    merged = combined_by_size(by_size, other)
    assert merged.comparable(20.0, 2.0).views == 5 and by_size.comparable(20.0, 2.0).views == 4
    everything = merged.comparable(45.0, 8.0)
    expected = model_of([*close, *far, far[0]])
    np.testing.assert_allclose(everything.mean, expected.mean)
    np.testing.assert_allclose(everything.squares, expected.squares, atol=1e-12)


def sized(percept, size: float):
    return dataclasses.replace(percept, box=BoundingBox2D(80.0, 60.0, size, size))


@pytest.mark.parametrize(("own", "other"), [(RED, GREEN), (GREEN, BLUE)])
def test_views_of_another_colour_rule_out_an_anchor_only_at_about_the_size_it_was_seen(own: int, other: int) -> None:
    """The anchor knows its colour from close views; a view three times smaller (from across the
    room) blends outline and background, and its colour is no evidence against it: it reacquires
    the anchor. At about the size the anchor was seen, a first such view is held apart and a
    second one rules the anchor out."""
    red = SceneObject("red", "cup", KITCHEN, colour=mug_colour(own))
    green = SceneObject("green", "cup", KITCHEN, colour=mug_colour(other))
    later = ColourEvidenceConfig().second_view_after + 0.1
    for size, ruled_out in ((20.0, True), (30.0, True), (60.0, False), (6.5, False)):
        anchoring, maker = rules(), PerceptMaker(seed=own + int(size))
        see(anchoring, maker, [red], 0.0)
        first = anchoring.process([sized(maker.percept(green, 60.0), size)], camera_view(), 60.0).percept_symbols
        assert first == (("",) if ruled_out else ("cup_1",)), size
        if ruled_out:
            second = anchoring.process([sized(maker.percept(green, 60.0 + later), size)], camera_view(), 60.0 + later)
            assert second.percept_symbols == ("cup_2",), size
    # A wider comparable_size takes the far view as evidence again.
    anchoring, maker = rules(ColourEvidenceConfig(comparable_size=4.0, second_view_after=0.0)), PerceptMaker(seed=3)
    see(anchoring, maker, [red], 0.0)
    assert anchoring.process([sized(maker.percept(green, 60.0), 60.0)], camera_view(), 60.0).percept_symbols == (
        "cup_2",)


def test_a_view_that_cannot_be_held_to_the_anchors_colour_neither_checks_nor_joins_it() -> None:
    """The swap seen first from afar: the green mug stands where the red one was, seen only close
    up. Its far views reacquire the red anchor (the rules read place and time), but their colour
    does not join the red mug's nor restart its clock; the first views at the red mug's size rule
    the anchor out. Without that, the far views made the red anchor's colour half green and the
    mission claimed the green mug (`swapped`, rules, seed 0, 3 December)."""
    red = SceneObject("red", "cup", KITCHEN, colour=mug_colour(RED))
    green = SceneObject("green", "cup", KITCHEN, colour=mug_colour(GREEN))
    anchoring, maker = rules(), PerceptMaker(seed=21)
    see(anchoring, maker, [red], 0.0)
    cup = anchoring.get("cup_1")
    views, seen = cup.colour.views, cup.colour_seen
    for frame in range(8):
        stamp = 60.0 + frame * FRAME
        result = anchoring.process([sized(maker.percept(green, stamp), 60.0)], camera_view(), stamp)
        assert result.percept_symbols == ("cup_1",)
    assert cup.colour.views == views and cup.colour_seen == seen
    assert sum(model.views for model in cup.colour_by_size.bands.values()) == views
    symbols = [anchoring.process([sized(maker.percept(green, 61.0 + frame * FRAME), 20.0)], camera_view(),
                                 61.0 + frame * FRAME).percept_symbols for frame in range(SUSPICION_FRAMES)]
    assert symbols[0] == ("",) and symbols[-1] == ("cup_2",)
    # While its colour is fresh, views of every size join it: approaching an object fills its sizes in.
    anchoring, maker = rules(), PerceptMaker(seed=22)
    see(anchoring, maker, [red], 0.0)
    anchoring.process([sized(maker.percept(red, 1.0), 60.0)], camera_view(), 1.0)
    assert len(anchoring.get("cup_1").colour_by_size.bands) == 2


@pytest.mark.parametrize(("own", "other", "size"), [(RED, GREEN, 60.0), (GREEN, BLUE, 6.5), (BLUE, RED, 70.0)])
def test_a_view_that_cannot_be_held_to_the_anchors_colour_is_not_reported_as_its_sighting(own, other, size) -> None:
    """Another object put in the anchor's place while the robot was away, seen on the way back only
    at a size the anchor has no views of: its views reacquire the anchor, but the anchor does not
    report them as its sighting (what approach_object waits for) until a view checks its colour:
    its own colour ends the doubt, another colour rules it out (`removed_while_a_twin_is_unseen`,
    network, seed 2, 6 December 2026: the cookbook claimed in front of a green book)."""
    mug = SceneObject("mug", "cup", KITCHEN, colour=mug_colour(own))
    stranger = SceneObject("stranger", "cup", KITCHEN, colour=mug_colour(other))
    anchoring, maker = rules(), PerceptMaker(seed=own + int(size))
    see(anchoring, maker, [mug], 0.0)
    cup = anchoring.get("cup_1")
    known = cup.last_seen
    for frame in range(6):
        stamp = 60.0 + frame * FRAME
        assert anchoring.process([sized(maker.percept(stranger, stamp), size)], camera_view(),
                                 stamp).percept_symbols == ("cup_1",)
    assert cup.last_seen == pytest.approx(60.0 + 5 * FRAME)  # matched: the rules read place and time
    assert cup.unverified_sightings == (known, pytest.approx(60.0 + 5 * FRAME))
    assert cup.last_sure_sighting == known and AnchorView.of(cup).last_seen == known
    restored = rules()
    restored.restore(json.loads(json.dumps(anchoring.snapshot())))
    assert restored.get("cup_1").last_sure_sighting == known
    # At the anchor's own size the stranger's colour is told: it rules the anchor out.
    symbols = [anchoring.process([maker.percept(stranger, 61.0 + frame * FRAME)], camera_view(),
                                 61.0 + frame * FRAME).percept_symbols for frame in range(SUSPICION_FRAMES)]
    assert symbols[-1] == ("cup_2",) and AnchorView.of(cup).last_seen == known
    # The same views of the anchor's own object, then one at its size: its colour checks, the doubt ends.
    anchoring, maker = rules(), PerceptMaker(seed=own)
    see(anchoring, maker, [mug], 0.0)
    cup = anchoring.get("cup_1")
    for frame in range(6):
        anchoring.process([sized(maker.percept(mug, 60.0 + frame * FRAME), size)], camera_view(), 60.0 + frame * FRAME)
    assert cup.last_sure_sighting < 60.0
    anchoring.process([maker.percept(mug, 61.0)], camera_view(), 61.0)
    assert cup.unverified_sightings is None and cup.last_sure_sighting == cup.last_seen == 61.0


def test_views_of_every_size_are_sightings_while_the_colour_is_fresh() -> None:
    """Within the absence after its colour was seen nothing has been swapped: a view of a new size is
    its sighting (and fills that size in)."""
    mug = SceneObject("mug", "cup", KITCHEN, colour=mug_colour(RED))
    anchoring, maker = rules(), PerceptMaker(seed=4)
    see(anchoring, maker, [mug], 0.0)
    anchoring.process([sized(maker.percept(mug, 2.0), 60.0)], camera_view(), 2.0)
    cup = anchoring.get("cup_1")
    assert cup.unverified_sightings is None and cup.last_sure_sighting == cup.last_seen == 2.0


def test_only_a_view_in_the_anchors_place_counts_against_it() -> None:
    """Another book of another colour 2 m away is within the table's reach of the long-unseen
    cookbook, and of course differs: it is another object, not a dispute of the cookbook (which once
    let one odd view of the cookbook itself rule its anchor out: `swapped`, rules, seed 0)."""
    red_book = SceneObject("cookbook", "book", KITCHEN, colour=mug_colour(RED))
    green_book = SceneObject("hall book", "book", (4.0, 0.3, 0.8), colour=mug_colour(GREEN))
    anchoring, maker = rules(), PerceptMaker(seed=31)
    see(anchoring, maker, [red_book], 0.0)
    see(anchoring, maker, [green_book], 60.0, frames=SUSPICION_FRAMES + 2)
    cookbook = anchoring.get("book_1")
    assert not cookbook.colour_disputed and cookbook.colour_suspected is None
    # The same view where the cookbook stood is one.
    see(anchoring, maker, [], 61.0, frames=1)
    moved_in = SceneObject("hall book", "book", KITCHEN, colour=mug_colour(GREEN))
    assert see(anchoring, maker, [moved_in], 62.0, frames=SUSPICION_FRAMES).percept_symbols == ("book_3",)
    assert cookbook.colour_disputed


def test_a_books_view_is_not_held_against_its_neighbour_on_the_shelf() -> None:
    """Two books of different colours 0.2 m apart, both unseen for a minute: each one's view stands
    within 0.5 m of the other's anchor, but nearer its own; neither is disputed, even when only one
    of them is seen."""
    red_book = SceneObject("red", "book", KITCHEN, colour=mug_colour(RED))
    green_book = SceneObject("green", "book", (KITCHEN[0], KITCHEN[1] + 0.2, KITCHEN[2]), colour=mug_colour(GREEN))
    anchoring, maker = rules(), PerceptMaker(seed=32)
    see(anchoring, maker, [red_book, green_book], 0.0)
    assert see(anchoring, maker, [red_book], 60.0, frames=SUSPICION_FRAMES + 2).percept_symbols == ("book_1",)
    neighbour = anchoring.get("book_2")
    assert not neighbour.colour_disputed and neighbour.colour_suspected is None


@pytest.mark.parametrize(("class_name", "size", "part", "own", "other"), [
    ("bicycle", (0.35, 1.6, 1.0), (0.15, 0.55, 1.0), RED, GREEN),
    ("tv", (1.2, 0.1, 0.7), (0.45, 0.1, 0.7), BLUE, 3),
    ("couch", (2.0, 0.9, 0.8), (0.9, 0.6, 0.8), GREEN, RED),
])
def test_a_part_of_a_large_object_is_no_colour_evidence_against_it(class_name, size, part, own, other) -> None:
    """A view of a large object showing a third of what its whole views showed (the rest beyond
    the depth, or behind something the partial-view tests cannot see) has a part's colours: it is
    no evidence that another object stands there, however its colours differ (`twin_moved`,
    network, seed 0: a bicycle's near half ruled its anchor out and was anchored anew). The same
    colours seen at the object's whole extent still rule it out."""
    whole = SceneObject(class_name, class_name, KITCHEN, size=size, colour=mug_colour(own))
    part_of_it = SceneObject(class_name, class_name, KITCHEN, size=part, colour=mug_colour(other))
    anchoring, maker = rules(), PerceptMaker(seed=own + other)
    see(anchoring, maker, [whole], 0.0)
    anchor = anchoring.get(f"{class_name}_1")
    views = anchor.colour.views
    result = see(anchoring, maker, [part_of_it], 60.0, frames=SUSPICION_FRAMES + 3)
    assert result.percept_symbols == (f"{class_name}_1",)
    assert not anchor.colour_disputed and anchor.colour_suspected is None
    assert anchor.colour.views == views  # nor does a part's colour join the object's
    another_whole = SceneObject("another", class_name, KITCHEN, size=size, colour=mug_colour(other))
    anchoring, maker = rules(), PerceptMaker(seed=own + other)
    see(anchoring, maker, [whole], 0.0)
    result = see(anchoring, maker, [another_whole], 60.0, frames=SUSPICION_FRAMES + 3)
    assert result.percept_symbols == (f"{class_name}_2",)


@pytest.mark.parametrize(("class_name", "known", "seen", "own", "other"), [
    # A dog's lower part hidden behind a sofa: the view shows 0.40 m of its 0.52 m.
    ("dog", (0.56, 0.25, 0.52), (0.56, 0.25, 0.40), RED, GREEN),
    # The anchor first knew only the top of a cat (its legs hidden), then the whole cat is seen.
    ("cat", (0.47, 0.2, 0.22), (0.47, 0.2, 0.32), BLUE, 3),
    # A dog first seen end-on, 0.27 m of its 0.55 m (small across the floor, not in height), then
    # side on (`large_object_wheeled_away`, network, seed 2, 7 December 2026).
    ("dog", (0.27, 0.22, 0.52), (0.55, 0.3, 0.52), 9, 14),
    # A horse first seen end-on, 0.6 m of its 1.4 m; then seen whole, side on.
    ("horse", (0.6, 0.5, 1.5), (1.4, 0.5, 1.5), GREEN, RED),
    # A television whose lower fifth and more is behind a cabinet.
    ("tv", (1.1, 0.1, 0.65), (1.1, 0.1, 0.48), 16, BLUE),
])
def test_a_view_showing_more_or_less_of_a_large_objects_height_or_length_is_no_colour_evidence(
        class_name, known, seen, own, other) -> None:
    """A large object's view and its anchor that saw different amounts of it (a part hidden
    behind furniture, or seen end-on, which neither the image's edge nor an occluder beside the
    box tells) show the colours of different parts: whichever of the two saw less, the view is no
    evidence that another object stands there (scenario suite, network, 6 December 2026: three
    duplicate anchors of the dog, each from a view ruled out by colour where one side had seen
    0.7-0.8 of the dog's height, or 0.6 of its length). The same colours at the extent the anchor
    knows still rule it out."""
    first = SceneObject(class_name, class_name, KITCHEN, size=known, colour=mug_colour(own))
    differently_seen = SceneObject(class_name, class_name, KITCHEN, size=seen, colour=mug_colour(other))
    anchoring, maker = rules(), PerceptMaker(seed=own + 3 * other)
    see(anchoring, maker, [first], 0.0)
    anchor = anchoring.get(f"{class_name}_1")
    assert anchor.colour.views >= ColourEvidenceConfig().minimum_views
    result = see(anchoring, maker, [differently_seen], 60.0, frames=SUSPICION_FRAMES + 3)
    assert result.percept_symbols == (f"{class_name}_1",)
    assert not anchor.colour_disputed and anchor.colour_suspected is None
    assert [a.symbol for a in anchoring.anchors] == [f"{class_name}_1"]
    another = SceneObject("another", class_name, KITCHEN, size=known, colour=mug_colour(other))
    anchoring, maker = rules(), PerceptMaker(seed=own + 3 * other)
    see(anchoring, maker, [first], 0.0)
    result = see(anchoring, maker, [another], 60.0, frames=SUSPICION_FRAMES + 3)
    assert result.percept_symbols == (f"{class_name}_2",)


def test_a_small_objects_view_measured_long_by_depth_noise_is_still_held_to_its_colour() -> None:
    """Only the anchor says what is large: a far view of a mug measured 0.4 m long (depth noise;
    tours of the suite's worlds measured far mugs 0.3-0.44 m long) where the red mug stood, of
    another colour, is held to the mug's colour and rules it out, as any view of about its size."""
    red = SceneObject("red", "cup", KITCHEN, colour=mug_colour(RED))
    green_measured_long = SceneObject("green", "cup", KITCHEN, size=(0.4, 0.1, 0.11), colour=mug_colour(GREEN))
    anchoring, maker = rules(), PerceptMaker(seed=17)
    see(anchoring, maker, [red], 0.0)
    result = see(anchoring, maker, [green_measured_long], 60.0, frames=SUSPICION_FRAMES + 3)
    assert result.percept_symbols == ("cup_2",)
    assert anchoring.get("cup_1").colour_disputed


def test_a_first_view_of_another_colour_is_held_until_a_second_one_confirms_it() -> None:
    red = SceneObject("red", "cup", KITCHEN, colour=mug_colour(RED))
    green = SceneObject("green", "cup", KITCHEN, colour=mug_colour(GREEN))
    anchoring, maker = rules(), PerceptMaker(seed=12)
    see(anchoring, maker, [red], 0.0)
    first = anchoring.process([maker.percept(green, 60.0)], camera_view(), 60.0)
    # Neither the anchor's (it is not reacquired by it) nor a new one; the anchor is not missing
    # either: the view may be it.
    assert first.percept_symbols == ("",) and first.unresolved == ("cup_1",)
    cup = anchoring.get("cup_1")
    assert cup.state is AnchorState.CONFIRMED and cup.colour_suspected == 60.0 and not cup.colour_disputed
    assert [anchor.symbol for anchor in anchoring.anchors] == ["cup_1"]
    # Too soon for a second view: still held, the suspicion still dates from the first.
    assert anchoring.process([maker.percept(green, 60.1)], camera_view(), 60.1).percept_symbols == ("",)
    assert cup.colour_suspected == 60.0
    # A view of its own colour in between is fused, and ends the suspicion.
    assert anchoring.process([maker.percept(red, 60.2)], camera_view(), 60.2).percept_symbols == ("cup_1",)
    assert cup.colour_suspected is None
    # After another absence: a suspicion too old to confirm (seconds later, another visit) is
    # raised anew, and a second view soon after that one confirms it.
    assert anchoring.process([maker.percept(green, 90.0)], camera_view(), 90.0).percept_symbols == ("",)
    assert anchoring.process([maker.percept(green, 94.5)], camera_view(), 94.5).percept_symbols == ("",)
    assert cup.colour_suspected == 94.5
    result = anchoring.process([maker.percept(green, 94.9)], camera_view(), 94.9)
    assert result.percept_symbols == ("cup_2",) and cup.colour_disputed
    # second_view_after 0: the first view rules the anchor out, as colour evidence once did.
    eager, maker = rules(ColourEvidenceConfig(second_view_after=0.0)), PerceptMaker(seed=12)
    see(eager, maker, [red], 0.0)
    assert eager.process([maker.percept(green, 60.0)], camera_view(), 60.0).percept_symbols == ("cup_2",)


def test_colours_by_size_survive_a_snapshot_and_older_snapshots_learn_colour_afresh() -> None:
    red = SceneObject("red", "cup", KITCHEN, colour=mug_colour(RED))
    anchoring, maker = rules(), PerceptMaker(seed=5)
    see(anchoring, maker, [red], 0.0)
    anchoring.process([sized(maker.percept(red, 1.0), 70.0)], camera_view(), 1.0)
    restored = rules()
    restored.restore(json.loads(json.dumps(anchoring.snapshot())))
    before, after = anchoring.get("cup_1").colour_by_size, restored.get("cup_1").colour_by_size
    assert sorted(after.bands) == sorted(before.bands) and len(after.bands) == 2
    for band, model in before.bands.items():
        assert after.bands[band].views == model.views
        np.testing.assert_allclose(after.bands[band].mean, model.mean)
    snapshot = anchoring.snapshot()
    del snapshot["anchors"][0]["colour_by_size"]
    older = rules()
    older.restore(snapshot)
    # Its colour is learnt afresh: one no view could be held to would never be checked again.
    assert older.get("cup_1").colour_by_size is None and older.get("cup_1").colour is None


# --- the side a view was seen from ------------------------------------------------------------

#: A large object seen from its two ends: from the camera at the origin (looking along +x) and
#: from a camera beyond it looking back (along -x).
DOG_PLACE = (2.5, 0.0, 0.3)
FRONT, BACK = camera_view(), camera_view(position=(5.0, 0.0, 1.0), yaw=math.pi)


def see_from(anchoring, maker, items, start, view, frames):
    result = None
    for frame in range(frames):
        stamp = start + frame * FRAME
        result = anchoring.process([maker.percept(item, stamp) for item in items], view, stamp)
    return result


@pytest.mark.parametrize(("front_hue", "back_hue"), [(RED, GREEN), (3, 9), (BLUE, 16)])
def test_a_view_from_a_side_the_anchor_never_saw_is_no_colour_evidence_against_it(front_hue, back_hue) -> None:
    """A many-coloured object (a dog's face and its flank) seen again after a while from its other
    side: its colour there is not the colour of the side its anchor knows, and it is still the
    same object (probes of the scenario suite, 5 December 2026: second anchors of the dog and the
    bird 0.03-0.05 m from their own)."""
    front = SceneObject("dog", "dog", DOG_PLACE, (0.55, 0.3, 0.5), colour=mug_colour(front_hue))
    back = SceneObject("dog", "dog", DOG_PLACE, (0.55, 0.3, 0.5), colour=mug_colour(back_hue))
    anchoring, maker = rules(), PerceptMaker(seed=front_hue)
    see_from(anchoring, maker, [front], 0.0, FRONT, 4)
    result = see_from(anchoring, maker, [back], 60.0, BACK, SUSPICION_FRAMES + 3)
    assert result.percept_symbols == ("dog_1",) and [a.symbol for a in anchoring.anchors] == ["dog_1"]
    # Held to every side (the old rule), the same views make a second anchor.
    every_side = rules(ColourEvidenceConfig(comparable_bearing=180.0))
    see_from(every_side, maker, [front], 0.0, FRONT, 4)
    assert see_from(every_side, maker, [back], 60.0, BACK, SUSPICION_FRAMES + 3).percept_symbols == ("dog_2",)


@pytest.mark.parametrize(("own", "other"), [(RED, GREEN), (GREEN, BLUE)])
def test_a_look_alike_put_in_an_objects_place_is_still_ruled_out_from_the_side_it_was_seen(own, other) -> None:
    """The swap seen from the side the camera knew the mug from, once more from the other end."""
    for view in (FRONT, BACK):
        mug = SceneObject("red", "cup", KITCHEN, colour=mug_colour(own))
        swapped_in = SceneObject("green", "cup", KITCHEN, colour=mug_colour(other))
        anchoring, maker = rules(), PerceptMaker(seed=own)
        see_from(anchoring, maker, [mug], 0.0, view, 4)
        assert see_from(anchoring, maker, [swapped_in], 60.0, view, SUSPICION_FRAMES + 3).percept_symbols == ("cup_2",)


def test_once_a_side_is_known_its_views_are_held_to_it() -> None:
    """Both sides seen while the colour was fresh: each later view is held to its own side's views."""
    front = SceneObject("dog", "dog", DOG_PLACE, (0.55, 0.3, 0.5), colour=mug_colour(RED))
    back = SceneObject("dog", "dog", DOG_PLACE, (0.55, 0.3, 0.5), colour=mug_colour(GREEN))
    other_back = SceneObject("other", "dog", DOG_PLACE, (0.55, 0.3, 0.5), colour=mug_colour(BLUE))
    anchoring, maker = rules(), PerceptMaker(seed=2)
    see_from(anchoring, maker, [front], 0.0, FRONT, 4)
    see_from(anchoring, maker, [back], 1.0, BACK, 4)
    assert [a.symbol for a in anchoring.anchors] == ["dog_1"]
    assert see_from(anchoring, maker, [back], 60.0, BACK, SUSPICION_FRAMES + 3).percept_symbols == ("dog_1",)
    assert see_from(anchoring, maker, [other_back], 120.0, BACK, SUSPICION_FRAMES + 3).percept_symbols == ("dog_2",)


def test_bearings_are_kept_in_sectors_and_survive_a_snapshot() -> None:
    model = ColourBySize()
    colour = mug_colour(RED)
    model.add(colour, 40.0, 0.1)
    model.add(colour, 40.0, math.pi)
    model.add(colour, 40.0, None)
    assert sorted(model.bands, key=view_key_order) == [(10, None), (10, 0), (10, 4)]
    assert model.comparable(40.0, 2.0, 0.2, 60.0).views == 2  # its own sector and the view of unknown bearing
    assert model.comparable(40.0, 2.0, None, 60.0).views == 3  # a view of unknown bearing is held to all
    assert model.comparable(40.0, 2.0, math.pi / 2, 30.0).views == 1
    for key in model.bands:
        assert view_key_from_text(view_key_text(key)) == key
    with pytest.raises(ConfigurationError, match="colour_comparable_bearing"):
        ColourEvidenceConfig(comparable_bearing=0.0)


#: The camera in the living room's doorway, looking into it (along +y), 3 m from the searched spot.
INTO_THE_LIVING_ROOM = camera_view(position=(1.5, 3.0, 1.0), yaw=math.pi / 2)


@pytest.mark.parametrize(("sought_hue", "seen_hue", "taken"), [
    (BLUE, 0, False), (BLUE, GREEN, False), (RED, GREEN, False), (BLUE, BLUE, True), (GREEN, GREEN, True)])
def test_a_view_of_another_colour_anywhere_in_a_searched_disc_is_not_the_sought_object(
        sought_hue, seen_hue, taken) -> None:
    """The search is under way before anything is seen there: the first view of a mug in the disc
    meets the sought anchor in the matching table itself, not in a merge of two anchors; its colour
    is held to the anchor's all the same (`moved_while_its_twin_is_watched`, network, seed 0: a
    white mug 2 m from the middle of the searched bedroom took the lost blue mug's symbol)."""
    sought = SceneObject("sought", "cup", KITCHEN, colour=mug_colour(sought_hue))
    seen = SceneObject("seen", "cup", tuple(LIVING_ROOM + np.array((0.6, 0.9, 0.0))), colour=mug_colour(seen_hue))
    anchoring, maker = rules(), PerceptMaker(seed=sought_hue + seen_hue)
    see(anchoring, maker, [sought], 0.0)
    see(anchoring, maker, [], 1.0, frames=1)
    search(anchoring, "cup_1", WALKED_THERE - 1.0)
    result = see_from(anchoring, maker, [seen], WALKED_THERE, INTO_THE_LIVING_ROOM, 4)
    assert result.percept_symbols == (("cup_1",) if taken else ("cup_2",))
    assert anchoring.get("cup_1").state is (AnchorState.CONFIRMED if taken else AnchorState.MISSING)


# --- two anchors held to each other side by side -----------------------------------------------


def sided_anchor(views: list[tuple[np.ndarray, float]], size: float = 40.0):
    """An anchor's colours as :func:`anchor_colours_differ` reads them, from (histogram, bearing) views."""
    whole, by_side = None, ColourBySize()
    for histogram, bearing in views:
        if whole is None:
            whole = ColourModel.of(histogram)
        else:
            whole.add(histogram)
        by_side.add(histogram, size, bearing)
    return dataclasses.make_dataclass("Coloured", ["colour", "colour_by_size", ("parts_fit", object, None)])(
        whole, by_side)


#: Bearings (object to camera) of three sides of an object, each at least 100 degrees from the next
#: so that no 45-degree sector either falls in is within 60 degrees of one the other falls in.
SIDE_A, SIDE_B, SIDE_C = math.radians(22.0), math.radians(142.0), math.radians(262.0)


@pytest.mark.parametrize(("share", "told_apart"), [(0.12, False), (0.14, False), (0.25, True), (0.4, True)])
@pytest.mark.parametrize(("first_side", "second_side"), [(SIDE_A, SIDE_B), (SIDE_B, SIDE_C), (SIDE_C, SIDE_A)])
def test_anchors_never_seen_from_a_common_side_differ_only_by_more_than_one_objects_sides_do(
        share, told_apart, first_side, second_side) -> None:
    """An object's colour from one side is not its colour from another (one object's sides differed
    by up to 0.17 on held-out houses); two anchors that never saw a common side are told apart by
    colour only beyond that (``minimum_difference_across_sides``)."""
    rng = np.random.default_rng(int(share * 100))
    first = sided_anchor([(view, first_side) for view in noisy_views(mug_colour(RED, share), 12, rng, 0.005)])
    second = sided_anchor([(view, second_side) for view in noisy_views(mug_colour(GREEN, share), 4, rng, 0.005)])
    config = ColourEvidenceConfig()
    assert colours_differ(first.colour, second.colour, config)  # the whole models differ either way
    assert anchor_colours_differ(first, second, config) is told_apart
    # Seen from a common side, the same difference tells them apart.
    same_side = sided_anchor([(view, first_side) for view in noisy_views(mug_colour(GREEN, share), 4, rng, 0.005)])
    assert anchor_colours_differ(first, same_side, config)
    # Anchors restored from an older snapshot, without views by side, are held to their whole models.
    assert anchor_colours_differ(first, dataclasses.replace(second, colour_by_size=None), config)
    # An anchor joined from parts of a large object is no colour evidence, from any side.
    assert not anchor_colours_differ(first, dataclasses.replace(same_side, parts_fit=np.ones(3)), config)
    # The threshold is a setting, at least the difference that counts from a common side.
    assert anchor_colours_differ(first, second, ColourEvidenceConfig(minimum_difference_across_sides=0.1))
    with pytest.raises(ConfigurationError, match="across_sides"):
        ColourEvidenceConfig(minimum_difference_across_sides=0.05)


@pytest.mark.parametrize("share", [0.12, 0.14, 0.2, 0.3])
@pytest.mark.parametrize("sides", [(SIDE_A, SIDE_A), (SIDE_A, SIDE_B)])
def test_the_gap_between_two_anchors_colours_is_the_largest_difference_that_counts(share, sides) -> None:
    """:func:`anchor_colour_gap` weighs what :func:`anchor_colours_differ` decides: 0 exactly where
    they do not differ, else the largest difference that counts (from a common side the views',
    from none the whole models', beyond what one object's sides differ by)."""
    rng = np.random.default_rng(int(share * 100))
    first = sided_anchor([(view, sides[0]) for view in noisy_views(mug_colour(RED, 0.3), 12, rng, 0.005)])
    second = sided_anchor([(view, sides[1]) for view in noisy_views(mug_colour(RED, 0.3 + share), 6, rng, 0.005)])
    config = ColourEvidenceConfig()
    gap = anchor_colour_gap(first, second, config)
    assert (gap > 0.0) is anchor_colours_differ(first, second, config)
    assert gap == anchor_colour_gap(second, first, config)
    shown = share > config.minimum_difference_across_sides or sides[0] == sides[1]
    assert gap == (pytest.approx(share, abs=0.02) if shown else 0.0)
    assert anchor_colour_gap(first, dataclasses.replace(second, parts_fit=np.ones(3)), config) == 0.0


def looking_at(target, bearing: float, distance: float = 3.0):
    """A camera ``distance`` m from ``target`` in the direction ``bearing`` (radians), facing it."""
    x, y = target[0] + distance * math.cos(bearing), target[1] + distance * math.sin(bearing)
    return camera_view(position=(x, y, 1.0), yaw=bearing + math.pi)


@pytest.mark.parametrize("found_from", [0.0, math.radians(300.0), math.radians(60.0)])
@pytest.mark.parametrize(("share", "found"), [(0.12, True), (0.14, True), (0.3, False)])
def test_a_large_object_found_from_another_side_than_it_was_known_is_found(found_from, share, found) -> None:
    """`large_object_wheeled_away`, network, seed 2 (6 December 2026): the bicycle, known from one
    end (seen here from bearing 180 degrees), was anchored anew from its other side where it was
    wheeled to; the search ruled its only candidate out by the two anchors' whole colours (0.116
    apart) and ended "not found". A candidate whose colour differs by more than one object's sides
    do is still ruled out. Where the dog was anchored anew the camera had never watched: the search
    records the find and takes it when it concludes; a candidate ruled out is neither."""
    known = SceneObject("dog", "dog", DOG_PLACE, (0.55, 0.3, 0.5), colour=mug_colour(RED, share))
    moved = SceneObject("dog", "dog", tuple(LIVING_ROOM), (0.55, 0.3, 0.5), colour=mug_colour(GREEN, share))
    anchoring, maker = rules(), PerceptMaker(seed=int(share * 100))
    see_from(anchoring, maker, [known], 0.0, FRONT, 4)
    see_from(anchoring, maker, [], 1.0, FRONT, 1)
    assert anchoring.get("dog_1").state is AnchorState.MISSING
    see_from(anchoring, maker, [moved], WALKED_THERE, looking_at(LIVING_ROOM, found_from), 4)
    assert anchoring.get("dog_2").state is AnchorState.CONFIRMED
    events = anchoring.expect("dog_1", Expectation.at(LIVING_ROOM, WALKED_THERE + 1.0, "living_room", "find",
                                                      radius=1.5)).events
    assert events == ()
    assert recorded(anchoring, "dog_1") == (AnchorState.MISSING, "dog_2" if found else "")
    merged = [(AnchorEventKind.FORGOTTEN, "dog_2"), (AnchorEventKind.CONFIRMED, "dog_1")]
    assert concluded(anchoring, "dog_1") == (merged if found else [])
    assert anchoring.get("dog_1").state is (AnchorState.CONFIRMED if found else AnchorState.MISSING)


@pytest.mark.parametrize(("own", "other", "apart"), [(RED, GREEN, 0.3), (BLUE, 16, 0.4), (3, 9, 0.25)])
def test_a_missing_anchor_taking_a_view_held_from_the_anchor_in_its_place_says_so(own, other, apart) -> None:
    """The first view of another colour standing in a confirmed anchor's place is held from it;
    a missing look-alike of the view's colour nearby may take it, and its reacquisition names the
    nearer anchor the view was kept from and why (twin_removed_from_the_shelf, scenario suite,
    network, seed 0, 5 December 2026: which rule kept the twin's anchor away was not known)."""
    here = SceneObject("here", "cup", KITCHEN, colour=mug_colour(own))
    beside = SceneObject("beside", "cup", tuple(np.asarray(KITCHEN) + (0.0, apart, 0.0)), colour=mug_colour(other))
    anchoring, maker = rules(), PerceptMaker(seed=5)
    here_symbol, beside_symbol = see(anchoring, maker, [here, beside], 0.0).percept_symbols
    see(anchoring, maker, [here], 1.0, frames=2)
    assert anchoring.get(beside_symbol).state is AnchorState.MISSING
    stranger = SceneObject("stranger", "cup", KITCHEN, colour=mug_colour(other))
    result = anchoring.process([maker.percept(stranger, 60.0)], camera_view(), 60.0)
    assert result.percept_symbols == (beside_symbol,)
    scored = next(event.details["scored"] for event in result.events if event.kind is AnchorEventKind.REACQUIRED)
    assert f"nearer, kept from it: {here_symbol} (confirmed, 0.0" in scored, scored
    gap = re.search(r"held apart by a first view of another colour \((\d\.\d\d) in the hue window at (\d+) deg: "
                    r"(\d\.\d\d) in its (\d+) views, (\d\.\d\d) in this one\)$", scored)
    assert gap, scored
    difference, window, known, views, seen = gap.groups()
    assert float(difference) == pytest.approx(abs(float(known) - float(seen)), abs=0.011)
    assert float(difference) > ColourEvidenceConfig().minimum_difference and int(views) >= 3
    # the window named is one of the two colours' own (a mug's colour sits in one hue bin)
    assert int(window) // 20 in {(own - 1) % 18, own, (own + 1) % 18, (other - 1) % 18, other, (other + 1) % 18}


def book_colour(hue_bin: int, mid: float, light: float, dark: float = 0.02, hue_share: float = 0.35) -> np.ndarray:
    """A book's colour: its cover's hue (split over the bin and the next, as a render's red is),
    and its grey pixels (pages, the cover's lit face) in the dark, mid and light bins."""
    histogram = np.zeros(COLOUR_BINS)
    histogram[[hue_bin, (hue_bin + 1) % HUE_BINS]] = (hue_share * 0.7, hue_share * 0.3)
    histogram[HUE_BINS:] = (dark, mid, light)
    return histogram / histogram.sum()


@pytest.mark.parametrize(("hue", "lit", "turned"), [(0, (0.34, 0.40), (0.07, 0.67)), (11, (0.5, 0.2), (0.2, 0.5)),
                                                    (6, (0.1, 0.6), (0.45, 0.25))])
def test_copies_of_one_make_lit_differently_agree_and_other_makes_do_not(hue, lit, turned) -> None:
    """Light moves a face's grey pixels between the mid and light bins, and changes no hue: two
    copies of one make, one turned from the light, agree (whole models and a single view), where
    the bins taken apart differed by 0.2-0.3; copies of another hue, or a black and a white one, do
    not."""
    rng, config = np.random.default_rng(hue), ColourEvidenceConfig()
    shelf = model_of(noisy_views(book_colour(hue, *lit), 8, rng))
    desk = model_of(noisy_views(book_colour(hue, *turned), 4, rng))
    assert np.max(np.abs(shelf.mean - desk.mean)) > 0.2  # the bins apart differ by far more than the noise
    assert colours_agree(shelf, desk, config) and colours_agree(desk, shelf, config)
    assert not view_differs(shelf, book_colour(hue, *turned), config)
    other_hue = model_of(noisy_views(book_colour((hue + 6) % HUE_BINS, *turned), 4, rng))
    assert not colours_agree(shelf, other_hue, config) and view_differs(shelf, book_colour((hue + 6) % HUE_BINS,
                                                                                               *turned), config)
    black = model_of(noisy_views(book_colour(hue, 0.05, 0.0, dark=0.6), 4, rng))
    assert not colours_agree(shelf, black, config)
    assert not colours_agree(shelf, None, config)  # an unknown colour agrees with nothing


@pytest.mark.parametrize(("hue", "lit", "turned"), [(0, (0.34, 0.40), (0.14, 0.60)), (11, (0.5, 0.2), (0.25, 0.45)),
                                                    (6, (0.1, 0.6), (0.4, 0.3))])
def test_a_view_of_the_anchors_object_lit_otherwise_is_not_held_apart_from_it(hue, lit, turned) -> None:
    """A book's own view, after a while, in its place, with some grey pixels gone from mid to light
    (its neighbour taken away, a face turned to the light): held apart from its own anchor, the
    removed twin's missing anchor took it (`twin_removed_from_the_shelf`, network, seed 0,
    6 December 2026: "0.19 in the mid grey bin: 0.34 in its 54 views, 0.14 in this one"). Such a
    view reacquires its anchor; a view of another hue there is still held apart."""
    book = SceneObject("book", "book", KITCHEN, size=(0.2, 0.05, 0.26), colour=book_colour(hue, *lit))
    anchoring, maker = rules(), PerceptMaker(seed=hue)
    see(anchoring, maker, [book], 0.0)
    lit_otherwise = SceneObject("book", "book", KITCHEN, size=(0.2, 0.05, 0.26), colour=book_colour(hue, *turned))
    assert anchoring.process([maker.percept(lit_otherwise, 60.0)], camera_view(), 60.0).percept_symbols == ("book_1",)
    other = SceneObject("other", "book", KITCHEN, size=(0.2, 0.05, 0.26),
                        colour=book_colour((hue + 6) % HUE_BINS, *turned))
    result = anchoring.process([maker.percept(other, 120.0)], camera_view(), 120.0)
    assert result.percept_symbols == ("",) and result.unresolved == ("book_1",)


@pytest.mark.parametrize(("sought_hue", "other_hue", "seed"), [(RED, GREEN, 1), (BLUE, RED, 2), (GREEN, 3, 3)])
def test_a_search_that_has_not_seen_the_look_of_what_it_met_looks_on_and_a_closer_view_decides(
    sought_hue: int, other_hue: int, seed: int
) -> None:
    """A search meets two mugs it has seen only too far to know their colours: nothing tells them
    apart yet, but nothing says they look alike either. It says nothing and looks on (the anchor
    records them); seen closer, the one of another colour is ruled out and the other is the sought
    one, taken when the search concludes. Had no closer view come, concluding would say that it
    cannot tell them apart, after a restart too. (Before: "they look alike" at the first stop, and
    the search ended there.)"""
    sought = SceneObject("sought", "cup", KITCHEN, colour=mug_colour(sought_hue))
    moved_to, other_at = (1.3, 5.9, 0.8), (1.8, 6.2, 0.8)
    colourless = [SceneObject("sought", "cup", moved_to), SceneObject("other", "cup", other_at)]
    coloured = [SceneObject("sought", "cup", moved_to, colour=mug_colour(sought_hue)),
                SceneObject("other", "cup", other_at, colour=mug_colour(other_hue))]
    outcomes = {}
    for closer in (True, False):
        anchoring, maker = rules(), PerceptMaker(seed=seed)
        see(anchoring, maker, [sought], 0.0)
        see(anchoring, maker, [], 1.0, frames=1)
        see(anchoring, maker, colourless, WALKED_THERE, camera=False)
        symbol_at = {tuple(moved_to): None, tuple(other_at): None}
        for place in symbol_at:
            symbol_at[place] = next(anchor.symbol for anchor in anchoring.anchors if anchor.symbol != "cup_1"
                                    and np.linalg.norm(anchor.position[:2] - np.array(place[:2])) < 0.2)
        moved_symbol, other_symbol = symbol_at[tuple(moved_to)], symbol_at[tuple(other_at)]
        assert kinds(search(anchoring, "cup_1", WALKED_THERE + 1.0)) == []
        assert set(anchoring.get("cup_1").look_pending) == {moved_symbol, other_symbol}
        assert anchoring.get("cup_1").indistinguishable_from == ()
        if closer:
            see(anchoring, maker, coloured, WALKED_THERE + 2.0, frames=8, camera=False)
            assert kinds(search(anchoring, "cup_1", WALKED_THERE + 3.0)) == []
        else:  # what the search met survives a restart
            restarted = rules()
            restarted.restore(json.loads(json.dumps(anchoring.snapshot())))
            assert restarted.get("cup_1").look_pending == anchoring.get("cup_1").look_pending
            anchoring = restarted
        outcomes[closer] = concluded(anchoring, "cup_1"), anchoring.get("cup_1").indistinguishable_from
    assert outcomes[True] == ([(AnchorEventKind.FORGOTTEN, moved_symbol), (AnchorEventKind.CONFIRMED, "cup_1")], ())
    assert outcomes[False][0] == [(AnchorEventKind.AMBIGUOUS, "cup_1")]
    assert set(outcomes[False][1]) == {moved_symbol, other_symbol}


@pytest.mark.parametrize(("sought_hue", "rival_hue", "seed"), [(RED, GREEN, 4), (BLUE, RED, 5), (RED, RED, 6),
                                                              (GREEN, GREEN, 7)])
def test_a_newcomer_that_may_be_either_of_two_lost_mugs_is_left_to_a_view_of_its_look(
    sought_hue: int, rival_hue: int, seed: int
) -> None:
    """Two mugs gone from the kitchen, one mug met by the search, seen only too far to know its
    colour: which lost mug it is (if either), nothing seen tells, but nothing says they look alike
    either. The search says nothing and looks on; seen closer, of the sought mug's colour, it is the
    sought one where the other lost mug is of another colour, and where both lost mugs are of its
    colour it cannot be told which. Had no closer view come, concluding says that it cannot tell
    which lost mug it is, naming both. (Before: "they look alike" at the first stop, both lost
    anchors undecided for good: `bicycle_wheeled_beside_another`, network, seed 0, 7 December 2026,
    two bicycles known only from end-on views.)"""
    sought = SceneObject("sought", "cup", KITCHEN, colour=mug_colour(sought_hue))
    rival = SceneObject("rival", "cup", (2.0, -0.5, 0.8), colour=mug_colour(rival_hue))
    moved_to = (1.3, 5.9, 0.8)
    outcomes = {}
    for closer in (True, False):
        anchoring, maker = rules(), PerceptMaker(seed=seed)
        see(anchoring, maker, [sought, rival], 0.0)
        rival_symbol = next(a.symbol for a in anchoring.anchors if a.position[1] < 0.0)
        sought_symbol = next(a.symbol for a in anchoring.anchors if a.symbol != rival_symbol)
        see(anchoring, maker, [], 1.0, frames=1)
        assert {a.state for a in anchoring.anchors} == {AnchorState.MISSING}
        see(anchoring, maker, [SceneObject("sought", "cup", moved_to)], WALKED_THERE, camera=False)
        [newcomer] = [a.symbol for a in anchoring.anchors if a.symbol not in (sought_symbol, rival_symbol)]
        assert kinds(search(anchoring, sought_symbol, WALKED_THERE + 1.0)) == []
        assert anchoring.get(sought_symbol).look_pending == (newcomer,)
        assert anchoring.get(sought_symbol).indistinguishable_from == ()
        assert anchoring.get(rival_symbol).indistinguishable_from == ()
        if closer:
            see(anchoring, maker, [SceneObject("sought", "cup", moved_to, colour=mug_colour(sought_hue))],
                WALKED_THERE + 2.0, frames=8, camera=False)
            search(anchoring, sought_symbol, WALKED_THERE + 3.0)
            if sought_hue == rival_hue:  # now they do look alike (said as the colour became known)
                assert set(anchoring.get(sought_symbol).indistinguishable_from) == {rival_symbol, newcomer}
                assert set(anchoring.get(rival_symbol).indistinguishable_from) == {sought_symbol, newcomer}
                continue
            assert recorded(anchoring, sought_symbol) == (AnchorState.MISSING, newcomer)
            assert anchoring.get(rival_symbol).indistinguishable_from == ()
        outcomes[closer] = concluded(anchoring, sought_symbol), anchoring.get(sought_symbol).indistinguishable_from
    if sought_hue != rival_hue:
        assert outcomes[True] == ([(AnchorEventKind.FORGOTTEN, newcomer), (AnchorEventKind.CONFIRMED, sought_symbol)],
                                  ())
    events, undecided = outcomes[False]
    assert set(events) == {(AnchorEventKind.AMBIGUOUS, sought_symbol), (AnchorEventKind.AMBIGUOUS, rival_symbol)}
    assert set(undecided) == {rival_symbol, newcomer}
