"""Partial views and large objects: a view that shows part of an object must not move its anchor
to the part's middle, nor make a second anchor of it."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from merlin2_sailor.anchoring import Anchoring, AnchoringConfig, AnchorState, Expectation
from merlin2_sailor.anchoring.anchor import Anchor
from merlin2_sailor.anchoring.anchor_comparison import identity_scores
from merlin2_sailor.anchoring.features import extent_slack
from merlin2_sailor.anchoring.partial_view import (
    PartialViewConfig,
    comparable_views,
    partial_views,
    smaller_than_known,
)
from merlin2_sailor.anchoring.rule_matcher import RuleMatcher
from merlin2_sailor.anchoring.snapshot import anchor_from_dict, anchor_to_dict
from merlin2_sailor.contract.percept import BoundingBox2D
from merlin2_sailor.errors import ConfigurationError, InvalidInputError

from .anchoring_scenes import AppearanceRules, PerceptMaker, SceneObject, camera_view, flat_depth

#: A 1.6 m long bicycle standing along +y, 3 m ahead of the camera at the origin (looking along +x).
BICYCLE = SceneObject("bicycle", "bicycle", (3.0, 0.0, 0.5), (0.35, 1.6, 1.0))
MIDDLE_BOX = BoundingBox2D.from_corners(60.0, 40.0, 100.0, 80.0)  # well inside the 160 x 120 image
EDGE_BOX = BoundingBox2D.from_corners(0.0, 40.0, 30.0, 80.0)  # cut by the left edge


def view_of(maker: PerceptMaker, item: SceneObject, stamp: float, box: BoundingBox2D,
            centre: tuple[float, float, float] | None = None, size: tuple[float, float, float] | None = None):
    percept = maker.percept(item, stamp, position=centre, with_embedding=False)
    return dataclasses.replace(percept, box=box, size=np.asarray(size or item.size, dtype=np.float64))


def test_a_box_at_the_image_edge_is_a_partial_view_and_one_inside_is_not(maker) -> None:
    percepts = [view_of(maker, BICYCLE, 0.0, MIDDLE_BOX), view_of(maker, BICYCLE, 0.0, EDGE_BOX)]
    assert partial_views(percepts, camera_view(), PartialViewConfig()) == [False, True]
    assert partial_views(percepts, None, PartialViewConfig()) == [False, False]  # no camera, no knowing


def test_a_nearer_surface_beside_the_box_makes_a_partial_view_and_the_floor_below_does_not(maker) -> None:
    cup = SceneObject("cup", "cup", (3.0, 0.0, 1.0))
    percept = view_of(maker, cup, 0.0, MIDDLE_BOX)
    depth = flat_depth(5.0)
    assert partial_views([percept], camera_view(depth=depth), PartialViewConfig()) == [False]
    beside = depth.copy()
    beside[40:80, 55:60] = 1.5  # a door frame just left of the box, much nearer than the cup
    assert partial_views([percept], camera_view(depth=beside), PartialViewConfig()) == [True]
    below = depth.copy()
    below[80:85, 60:100] = 2.9  # what the cup stands on, just below it and a little nearer
    assert partial_views([percept], camera_view(depth=below), PartialViewConfig()) == [False]
    no_depth = flat_depth(np.nan)
    assert partial_views([percept], camera_view(depth=no_depth), PartialViewConfig()) == [False]


def test_partial_view_configuration_is_checked() -> None:
    with pytest.raises(ConfigurationError, match="occluder_margin"):
        PartialViewConfig(occluder_margin=0.0)
    with pytest.raises(ConfigurationError, match="strip_width"):
        PartialViewConfig(strip_width=0)


def seen_whole_twice(maker: PerceptMaker, symbol: str, item: SceneObject) -> Anchor:
    """An anchor of ``item`` from two whole views, so its extent is corroborated."""
    fusion = AnchoringConfig().fusion
    anchor = Anchor.from_percept(symbol, view_of(maker, item, 0.0, MIDDLE_BOX), None, fusion)
    anchor.absorb(view_of(maker, item, 0.1, MIDDLE_BOX), None, fusion)
    return anchor


def test_a_much_smaller_view_of_a_large_object_seen_whole_is_partial(maker) -> None:
    once = Anchor.from_percept("bicycle_1", view_of(maker, BICYCLE, 0.0, MIDDLE_BOX), None,
                               AnchoringConfig().fusion)
    end_on = view_of(maker, BICYCLE, 1.0, MIDDLE_BOX, size=(0.35, 0.3, 1.0))
    assert not smaller_than_known(end_on, once)  # one box may have been a detector's slip
    anchor = seen_whole_twice(maker, "bicycle_1", BICYCLE)
    assert smaller_than_known(end_on, anchor)
    assert not smaller_than_known(view_of(maker, BICYCLE, 1.0, MIDDLE_BOX), anchor)
    mug = SceneObject("mug", "cup", (3.0, 0.0, 0.8))
    mug_anchor = Anchor.from_percept("cup_1", view_of(maker, mug, 0.0, MIDDLE_BOX), None, AnchoringConfig().fusion)
    tiny = view_of(maker, mug, 1.0, MIDDLE_BOX, size=(0.03, 0.03, 0.1))
    assert not smaller_than_known(tiny, mug_anchor)  # small objects: noise, not a partial view


def test_the_extent_slack_forgives_half_of_what_exceeds_a_small_object() -> None:
    np.testing.assert_allclose(extent_slack(np.array([[0.1, 0.1, 0.1], [0.35, 1.6, 1.0], [0.3, 0.3, 2.0]])),
                               [0.0, 0.65, 0.0])


@pytest.mark.parametrize(("offset", "slack"), [((0.0, 0.7), 0.65), ((0.7, 0.0), 0.025), ((0.0, 0.0), 0.65),
                                               ((0.5, 0.5), (1.95 / 2 ** 0.5 - 0.3) / 2)])
def test_the_slack_along_a_line_forgives_a_large_objects_extent_along_it_only(offset, slack) -> None:
    """A bicycle standing along y: 0.65 m along it, half of what its 0.35 m width exceeds a small
    object's across it; a zero (or vertical) offset is forgiven as in any direction."""
    from merlin2_sailor.anchoring.features import extent_slack_along
    bicycle = np.array((0.35, 1.6, 1.0))
    assert float(extent_slack_along(np.array((*offset, 0.0)), bicycle)) == pytest.approx(slack)


def test_a_side_view_is_forgiven_its_length_not_its_width_by_the_rules() -> None:
    """The run's boxes: the wheeled bicycle's side (0.07 x 1.59 m) beside the other bicycle's end
    anchor 0.56 m across it, and beside its own, 0.11 m away: by place, only its own is near."""
    from merlin2_sailor.anchoring.features import AnchorColumns, PerceptColumns, pair_features
    side = view_of(PerceptMaker(seed=1), BICYCLE, 10.0, MIDDLE_BOX, centre=(3.26, 6.6, 0.59), size=(0.07, 1.59, 0.81))
    other = Anchor("bicycle_3", "bicycle", np.array((2.70, 6.64, 0.49)), np.array((0.32, 0.16, 1.0)), 0.0, 9.0)
    own = Anchor("bicycle_5", "bicycle", np.array((3.30, 6.7, 0.5)), np.array((0.34, 0.41, 1.0)), 0.0, 9.0)
    features = pair_features(PerceptColumns.from_percepts([side]), AnchorColumns.from_anchors([other, own]),
                             np.array([0, 0]), np.array([0, 1]), RuleMatcher().feature_config, False)
    assert features.footprint_distance[0] == 0.0  # forgiven in every direction: the network's input
    assert features.place_distance[0] == pytest.approx(0.56, abs=0.01)
    assert features.place_distance[1] == 0.0
    other_score, own_score = RuleMatcher().score_pairs(features)
    assert own_score == pytest.approx(1.0) and other_score < 0.25  # 1.0 both, forgiven in every direction


def test_partial_views_neither_duplicate_a_large_object_nor_drag_its_anchor(make_anchoring, maker) -> None:
    anchoring = make_anchoring()
    camera = camera_view()
    for frame in range(3):  # whole views
        anchoring.process([view_of(maker, BICYCLE, frame * 0.1, MIDDLE_BOX)], camera, frame * 0.1)
    [bicycle] = anchoring.anchors
    assert bicycle.state is AnchorState.CONFIRMED
    # Seen end-on past a door frame, from the south, many times: only the near end, 0.6 m from the
    # middle (its box is placed at the middle, object_centre.py; the slack forgives the rest).
    near_end = (3.0, -0.6, 0.5)
    from_the_south = camera_view((3.0, -4.0, 1.0), yaw=np.pi / 2.0)
    for frame in range(3, 60):
        result = anchoring.process(
            [view_of(maker, BICYCLE, frame * 0.1, MIDDLE_BOX, centre=near_end, size=(0.35, 0.4, 1.0))],
            from_the_south, frame * 0.1,
        )
        assert result.percept_symbols == (bicycle.symbol,), f"frame {frame}: a second bicycle"
    assert len(anchoring) == 1
    assert np.linalg.norm(bicycle.position - np.array(BICYCLE.position)) < 0.05
    assert bicycle.size[1] == pytest.approx(1.6, rel=0.05)


def test_without_the_extent_slack_the_same_near_end_would_be_a_new_anchor(maker) -> None:
    """What the slack is for: the rule matcher alone puts 0.6 m beyond its tolerance."""
    small = SceneObject("box", "bicycle", (3.0, 0.0, 0.5), (0.3, 0.3, 1.0))
    anchoring = Anchoring()
    camera = camera_view()
    for frame in range(3):
        anchoring.process([view_of(maker, small, frame * 0.1, MIDDLE_BOX)], camera, frame * 0.1)
    result = anchoring.process([view_of(maker, small, 0.3, MIDDLE_BOX, centre=(3.0, -0.6, 0.5))], camera, 0.3)
    assert result.acquired


def test_an_anchor_acquired_from_a_cut_off_view_moves_to_its_first_whole_view(make_anchoring, maker) -> None:
    anchoring = make_anchoring()
    camera = camera_view()
    anchoring.process([view_of(maker, BICYCLE, 0.0, EDGE_BOX, centre=(3.0, 0.5, 0.5), size=(0.35, 0.5, 1.0))],
                      camera, 0.0)
    anchoring.process([view_of(maker, BICYCLE, 0.1, MIDDLE_BOX)], camera, 0.1)
    [bicycle] = anchoring.anchors
    assert np.linalg.norm(bicycle.position - np.array(BICYCLE.position)) < 0.05
    assert bicycle.whole_views == 1


def test_whole_views_survive_a_snapshot(maker) -> None:
    anchor = Anchor.from_percept("bicycle_1", view_of(maker, BICYCLE, 0.0, MIDDLE_BOX), None,
                                 AnchoringConfig().fusion)
    assert anchor_from_dict(anchor_to_dict(anchor)).whole_views == 1
    legacy = anchor_to_dict(anchor)
    del legacy["whole_views"]  # a snapshot saved before the field existed
    assert anchor_from_dict(legacy).whole_views == 0



def looks(maker: PerceptMaker, identity: str) -> np.ndarray:
    return maker.appearance(identity).copy()


def test_a_part_is_not_compared_by_its_look_with_a_learned_matcher(maker) -> None:
    """With appearance in the matching function: the bicycle's whole views fill its gallery; a
    view of its near end (a part, which looks like nothing of the whole) is scored without its
    look, as the rules score it, and neither makes a second bicycle nor joins the gallery; a whole
    view that looks like another object in the same place is still told apart by its look."""
    anchoring = Anchoring(AnchoringConfig(), matcher=AppearanceRules())
    camera = camera_view()
    whole = looks(maker, "bicycle")
    for frame in range(3):
        percept = dataclasses.replace(view_of(maker, BICYCLE, frame * 0.1, MIDDLE_BOX), embedding=whole)
        anchoring.process([percept], camera, frame * 0.1)
    [bicycle] = anchoring.anchors
    gallery_before = bicycle.gallery.copy()
    part_look = looks(maker, "a bicycle's near end")
    for frame, (box, centre, size) in enumerate([
        (MIDDLE_BOX, (3.0, -0.6, 0.5), (0.35, 0.4, 1.0)),  # end-on: much less than the known extent
        (EDGE_BOX, (3.0, 0.4, 0.5), (0.35, 0.8, 1.0)),  # cut by the image's edge
    ], start=3):
        part = dataclasses.replace(view_of(maker, BICYCLE, frame * 0.1, box, centre=centre, size=size),
                                   embedding=part_look)
        result = anchoring.process([part], camera, frame * 0.1)
        assert result.percept_symbols == (bicycle.symbol,), f"{box}: a part made a second bicycle"
    np.testing.assert_array_equal(bicycle.gallery, gallery_before)
    other_look = dataclasses.replace(view_of(maker, BICYCLE, 0.6, MIDDLE_BOX), embedding=looks(maker, "a trolley"))
    assert anchoring.process([other_look], camera, 0.6).acquired, "a whole view's look must still count"


def test_comparable_views_are_whole_views_of_no_less_than_the_known_extent(maker) -> None:
    fusion = AnchoringConfig().fusion
    bicycle = seen_whole_twice(maker, "bicycle_1", BICYCLE)
    mug = SceneObject("mug", "cup", (3.0, 0.5, 0.8))
    mug_anchor = Anchor.from_percept("cup_1", view_of(maker, mug, 0.0, MIDDLE_BOX), None, fusion)
    percepts = [
        view_of(maker, BICYCLE, 1.0, MIDDLE_BOX),  # whole
        view_of(maker, BICYCLE, 1.0, MIDDLE_BOX, size=(0.35, 0.3, 1.0)),  # end-on
        view_of(maker, BICYCLE, 1.0, EDGE_BOX),  # cut by the edge
        view_of(maker, mug, 1.0, MIDDLE_BOX, size=(0.03, 0.03, 0.1)),  # small: noise for a mug, no view of a bicycle
    ]
    sizes = np.array([percept.size for percept in percepts])
    comparable = comparable_views(sizes, [True, True, False, True], [bicycle, mug_anchor])
    assert comparable.tolist() == [[True, True], [False, True], [False, False], [False, True]]
    # no camera: the edge is not known, the extent still tells
    assert comparable_views(sizes, None, [bicycle, mug_anchor]).tolist() == [
        [True, True], [False, True], [True, True], [False, True]]
    never_whole = Anchor.from_percept("bicycle_2", view_of(maker, BICYCLE, 0.0, EDGE_BOX), None, fusion, partial=True)
    assert comparable_views(sizes[1:2], [True], [never_whole]).tolist() == [[True]]


@pytest.mark.parametrize("part_first", [False, True], ids=["part seen after the whole", "part seen first"])
def test_an_anchor_of_a_part_and_one_of_the_whole_are_compared_without_their_looks(maker, part_first) -> None:
    """Identity repair compares anchors as matching compares percepts: a newer anchor that saw the
    bicycle only end-on is judged by class, place and time against the lost whole one, and so is
    the mirror case (the end anchored first, the whole bicycle later under a second symbol, the
    end then lost: scenario suite, 4 December, a duplicate). A newer anchor of the same extent
    that looks like something else is still told apart by its look."""
    fusion = AnchoringConfig().fusion
    whole_view = view_of(maker, BICYCLE, 5.0 if part_first else 0.0, MIDDLE_BOX)
    part_view = view_of(maker, BICYCLE, 0.0 if part_first else 5.0, MIDDLE_BOX, size=(0.13, 0.46, 1.0))
    whole = Anchor.from_percept("bicycle_w", whole_view, looks(maker, "bicycle"), fusion)
    whole.absorb(dataclasses.replace(whole_view, stamp=whole_view.stamp + 0.1), looks(maker, "bicycle"), fusion)
    part = Anchor.from_percept("bicycle_p", part_view, looks(maker, "a bicycle's near end"), fusion)
    newer, lost = (whole, part) if part_first else (part, whole)
    by_rules = identity_scores(RuleMatcher(), [newer], lost)
    assert by_rules[0] > 0.5
    np.testing.assert_allclose(identity_scores(AppearanceRules(), [newer], lost), by_rules)
    other_look = Anchor.from_percept("bicycle_o", view_of(maker, BICYCLE, 9.0, MIDDLE_BOX), looks(maker, "a trolley"),
                                     fusion)
    [told_apart] = identity_scores(AppearanceRules(), [other_look], whole)
    assert told_apart < 0.5 * identity_scores(RuleMatcher(), [other_look], whole)[0]


def test_a_caller_that_knows_which_views_are_cut_says_so_without_a_camera(maker) -> None:
    """A replay of rendered scenes has no camera image to tell a cut view by, but its renderer knows
    which views are cut: told so, the core scores such a view without its look, as the node does
    from its camera; not told, the same view is a whole view whose look says another object."""
    cut_box = BoundingBox2D.from_corners(10.0, 40.0, 40.0, 80.0)  # only its flag says it is cut
    whole = looks(maker, "bicycle")
    part = view_of(maker, BICYCLE, 0.3, cut_box, centre=(3.0, 0.4, 0.5), size=(0.35, 1.0, 1.0))
    part = dataclasses.replace(part, embedding=looks(maker, "a bicycle's near end"))
    outcomes = {}
    for told in (True, False):
        anchoring = Anchoring(AnchoringConfig(), matcher=AppearanceRules())
        for frame in range(3):
            view = dataclasses.replace(view_of(maker, BICYCLE, frame * 0.1, MIDDLE_BOX), embedding=whole)
            anchoring.process([view], None, frame * 0.1, partial=[False] if told else None)
        outcomes[told] = anchoring.process([part], None, 0.3, partial=[True] if told else None)
    assert outcomes[True].percept_symbols == ("bicycle_1",) and not outcomes[True].acquired
    assert outcomes[False].acquired, "untold, the cut view's look must count (else this test shows nothing)"
    with pytest.raises(InvalidInputError, match="2 partial-view flags for 1 percepts"):
        Anchoring(AnchoringConfig(), matcher=AppearanceRules()).process([part], None, 0.3, partial=[True, False])


def test_one_box_around_two_neighbours_does_not_make_their_views_its_parts(maker) -> None:
    """A detector's single "cup" box around a mug and the book beside it is a 0.68 m cup; that
    one view must not make every later view of the real mug (a fifth of it) a part of the false
    anchor, which would then be confirmed by the mug's views while the mug's own anchor went
    missing beside it (scenario suite, `twin_moved`, network, seed 4: the hall's mug under two
    symbols for the whole mission). With a matcher that reads appearance: the rules, which read
    neither look nor size, score the box and the mug's view alike against the mug's anchor."""
    mug = SceneObject("mug", "cup", (3.0, 0.3, 0.85))
    anchoring = Anchoring(AnchoringConfig(), matcher=AppearanceRules())
    camera = camera_view()
    look = looks(maker, "mug")

    def mug_view(stamp: float):
        return dataclasses.replace(view_of(maker, mug, stamp, MIDDLE_BOX), embedding=look)

    for frame in range(3):
        anchoring.process([mug_view(frame * 0.1)], camera, frame * 0.1)
    [mug_anchor] = anchoring.anchors
    merged = dataclasses.replace(
        view_of(maker, mug, 0.3, BoundingBox2D.from_corners(50.0, 30.0, 110.0, 80.0), centre=(3.0, 0.17, 0.93),
                size=(0.3, 0.68, 0.23)),
        embedding=looks(maker, "a mug and a book"))
    anchoring.process([mug_view(0.3), merged], camera, 0.3)
    assert len(anchoring) == 2, "the slip's box makes a tentative anchor of its own"
    for frame in range(4, 40):
        result = anchoring.process([mug_view(frame * 0.1)], camera, frame * 0.1)
        assert result.percept_symbols == (mug_anchor.symbol,), f"frame {frame}: the mug seen as another anchor"
    assert mug_anchor.state is AnchorState.CONFIRMED
    assert [anchor.symbol for anchor in anchoring.anchors if anchor.state is AnchorState.CONFIRMED] == [
        mug_anchor.symbol]


def searched_bicycle(maker: PerceptMaker, searched_at: tuple[float, float, float]) -> tuple[Anchoring, Anchor]:
    """The bicycle seen whole four times, then missing, and sought by a search 1.5 m around
    ``searched_at``, which puts its anchor there until a view confirms it."""
    anchoring = Anchoring()
    camera = camera_view()
    for frame in range(4):
        anchoring.process([view_of(maker, BICYCLE, frame * 0.1, MIDDLE_BOX)], camera, frame * 0.1,
                          partial=[False])
    bicycle = anchoring.get("bicycle_1")
    bicycle.state, bicycle.missing_since, bicycle.lost_after = AnchorState.MISSING, 1.0, 0.3
    anchoring.expect("bicycle_1", Expectation.at(np.array(searched_at), 5.0, "hall", "find_object", 1.5))
    return anchoring, bicycle


def test_a_search_confirmed_by_a_partial_view_puts_the_anchor_where_it_was_seen(maker) -> None:
    """Perception outranks expectation: a search put the missing bicycle's anchor in the middle of
    the searched disc, and the views that find it there are of a part (through a door frame). A
    partial view does not move an anchor seen whole, but the disc's middle is no place the object
    was seen: once the search is confirmed, the anchor is where the view saw it."""
    anchoring, bicycle = searched_bicycle(maker, (3.0, 2.0, 0.5))
    assert bicycle.position[:2] == pytest.approx((3.0, 2.0))
    part_seen = (3.0, 2.6, 0.5)
    for frame in range(12):
        stamp = 6.0 + frame * 0.1
        anchoring.process([view_of(maker, BICYCLE, stamp, EDGE_BOX, centre=part_seen, size=(0.35, 0.5, 1.0))],
                          None, stamp, partial=[True])
        if bicycle.state is AnchorState.CONFIRMED:
            break
    assert bicycle.state is AnchorState.CONFIRMED and bicycle.expectation is None
    assert np.linalg.norm(bicycle.position[:2] - np.array(part_seen[:2])) < 0.05


@pytest.mark.parametrize("cut", [False, True], ids=["whole", "cut"])
@pytest.mark.parametrize(("viewpoint", "face_centre"), [((3.0, 1.4, 1.0), (3.0, 2.35, 0.5)),
                                                        ((3.0, 4.6, 1.0), (3.0, 3.65, 0.5)),
                                                        ((2.2, 1.5, 1.0), (2.95, 2.3, 0.5))])
def test_a_search_confirmed_by_a_view_of_the_near_face_puts_the_anchor_beyond_it(
    maker, viewpoint, face_centre, cut
) -> None:
    """Seen end-on, a bicycle the search sought shows only its near face: a box 0.3 m deep where
    the bicycle is 1.6 m long. The rest is beyond the face, away from the camera, so its middle is
    half the shortfall farther along the line of sight, from whichever side; so too where the
    camera's tests saw the view cut (a door frame takes from its width, not its depth: the found
    bicycle placed at its near end, `bicycle_wheeled_beside_another`, network, seeds 0 and 2)."""
    anchoring, bicycle = searched_bicycle(maker, (3.0, 3.0, 0.5))
    moved_to = np.array((3.0, 3.0))
    for frame in range(12):
        stamp = 6.0 + frame * 0.1
        face = view_of(maker, BICYCLE, stamp, MIDDLE_BOX, centre=face_centre, size=(0.35, 0.3, 1.0))
        anchoring.process([dataclasses.replace(face, viewpoint=np.asarray(viewpoint))], None, stamp,
                          partial=[cut])
        if bicycle.state is AnchorState.CONFIRMED:
            break
    assert bicycle.state is AnchorState.CONFIRMED and bicycle.expectation is None
    assert np.linalg.norm(bicycle.position[:2] - moved_to) < 0.25  # the face's own centre is 0.65 m off
    assert bicycle.size[1] == pytest.approx(1.6, abs=0.1)  # a face is no whole view: the extent stays


@pytest.mark.parametrize(("size", "whole"), [((0.35, 1.6, 1.0), True), ((1.5, 0.36, 0.95), True),
                                             ((0.35, 1.2, 1.0), False), ((0.35, 1.6, 0.6), False)],
                         ids=["all of it", "all of it, turned", "a shorter piece", "its lower part"])
def test_a_view_spanning_the_class_s_whole_extent_lacks_nothing(size, whole) -> None:
    from merlin2_sailor.anchoring.partial_view import spans_known_whole
    assert spans_known_whole(np.array(size), np.array((1.6, 0.35, 1.0))) is whole
    assert spans_known_whole(np.array(size), None) is False  # no whole one seen: nothing to span


def test_a_whole_bicycle_touching_the_images_edge_is_a_whole_view_once_one_was_seen(make_anchoring, maker) -> None:
    """Cut by the camera's test (its box touches the edge), a view as long and high as the whole
    bicycle seen before is whole all the same: it counts as a whole view of its anchor; a piece
    with the same box stays partial."""
    anchoring = make_anchoring()
    camera = camera_view()
    for frame in range(3):
        anchoring.process([view_of(maker, BICYCLE, frame * 0.1, MIDDLE_BOX)], camera, frame * 0.1)
    [bicycle] = anchoring.anchors
    before = bicycle.whole_views
    anchoring.process([view_of(maker, BICYCLE, 0.3, EDGE_BOX, size=(0.35, 0.9, 1.0))], camera, 0.3)
    assert bicycle.whole_views == before  # a piece, cut: partial
    anchoring.process([view_of(maker, BICYCLE, 0.4, EDGE_BOX, size=(0.36, 1.62, 0.98))], camera, 0.4)
    assert bicycle.whole_views == before + 1
