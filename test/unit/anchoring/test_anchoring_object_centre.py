"""A large object's view is placed at the object's middle, not on the face the camera saw, and two
ends side by side are two objects.

The case comes from the scenario suite (`bicycle_wheeled_beside_another`, network, 7 December
2026): two bicycles 0.65 m apart, seen only end-on from a doorway, were anchored at their near ends;
a later view of one's side, cut by the door frame, stood about as far from both anchors and went to
the other bicycle's, and two near ends never seen at one time were joined as parts of one bicycle
lying across them. Tested on the geometry alone (ends, sides, pieces, from every side), on the parts
rule, and frame by frame through the anchoring core with the rules as the matcher (every view cut,
so no look is compared: place is the only evidence).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from merlin2_sailor.anchoring import AnchorEventKind, Anchoring, AnchoringConfig
from merlin2_sailor.anchoring.lifecycle import LifecycleConfig
from merlin2_sailor.anchoring.object_centre import long_axis_shown, object_centre, placed_on_objects
from merlin2_sailor.anchoring.rule_matcher import RuleMatcher

from .anchoring_scenes import PerceptMaker, SceneObject
from .test_anchoring_parts import SLACK, bicycle, decide, seen_whole_elsewhere

KNOWN = np.array((1.6, 0.35, 1.0))  # a bicycle's turned extent: long side, short side, height


def view(position, size, viewpoint, class_name: str = "bicycle"):
    percept = PerceptMaker(seed=1).percept(SceneObject("b", class_name, tuple(position), tuple(size)), 0.0,
                                           with_embedding=False)
    return dataclasses.replace(percept, position=np.array(position, dtype=float), size=np.array(size, dtype=float),
                               viewpoint=None if viewpoint is None else np.array(viewpoint, dtype=float))


@pytest.mark.parametrize(("size", "axis"), [
    ((0.35, 0.05, 1.0), 1), ((0.05, 0.35, 1.0), 0),  # an end, seen along y / along x
    ((0.30, 0.26, 0.9), 1),  # an end the door frame cut a little
    ((0.50, 0.33, 1.0), 0),  # a piece of its side seen across its thickness
    ((0.35, 0.35, 1.0), None),  # spans the short side both ways: which way it stands cannot be told
    ((0.05, 1.50, 1.0), None), ((0.35, 1.60, 1.0), None),  # its side; the whole of it
    ((0.15, 0.05, 1.0), None),  # a piece narrower than the bicycle is wide
])
def test_a_box_spanning_the_short_side_says_the_long_side_runs_the_other_way(size, axis) -> None:
    assert long_axis_shown(np.array(size), KNOWN) == axis


def test_a_class_about_as_long_as_wide_shows_no_long_side() -> None:
    assert long_axis_shown(np.array((0.3, 0.05, 0.5)), np.array((0.4, 0.3, 0.5))) is None


@pytest.mark.parametrize(("viewpoint", "expected"), [
    ((3.0, 0.0, 1.0), (3.0, 3.0)),  # from the south, end-on: the middle 0.65 m beyond the face
    ((3.6, 3.5, 1.0), (3.0, 1.7)),  # from the north(-east): beyond, the other way
    ((0.0, 2.35, 1.0), (3.625, 2.35)),  # from the west the same box reads as an end too: the view alone tells
    (None, (3.0, 2.35)),  # no viewpoint: nothing to tell the far side by
])
def test_an_ends_middle_lies_beyond_it_by_what_the_view_lacks_of_the_long_side(viewpoint, expected) -> None:
    percept = view((3.0, 2.35, 0.5), (0.35, 0.3, 1.0), viewpoint)
    centre = object_centre(percept, KNOWN)
    assert centre[:2] == pytest.approx(expected)
    assert centre[2] == pytest.approx(0.5)


@pytest.mark.parametrize(("viewpoint", "expected_x"), [((5.0, 6.6, 1.0), 3.30), ((1.0, 6.3, 1.0), 3.60)])
def test_a_sides_middle_lies_beyond_it_by_half_the_short_side(viewpoint, expected_x) -> None:
    """The east face of a bicycle standing along y, 0.05 m deep in the view: its middle is 0.15 m
    behind it, away from the camera, from either side."""
    centre = object_centre(view((3.45, 6.6, 0.5), (0.05, 1.5, 1.0), viewpoint), KNOWN)
    assert centre[:2] == pytest.approx((expected_x, 6.6))


@pytest.mark.parametrize("size", [(0.15, 0.05, 1.0), (0.35, 1.6, 1.0), (1.6, 0.35, 1.0)],
                         ids=["a narrow piece", "whole, end-on", "whole, from its side"])
def test_a_piece_narrower_than_the_object_and_a_whole_view_stay_where_they_are(size) -> None:
    percept = view((3.0, 2.35, 0.5), size, (3.0, 0.0, 1.0))
    assert object_centre(percept, KNOWN)[:2] == pytest.approx((3.0, 2.35))


def test_only_views_of_a_class_with_a_known_extent_are_moved() -> None:
    end = view((3.0, 2.35, 0.5), (0.35, 0.3, 1.0), (3.0, 0.0, 1.0))
    mug = view((1.0, 1.0, 0.8), (0.1, 0.1, 0.1), (1.0, 0.0, 1.0), class_name="cup")
    tv = view((5.0, 1.0, 0.8), (0.05, 0.3, 0.5), (1.0, 1.0, 1.0), class_name="tv")
    placed = placed_on_objects([end, mug, tv], {"bicycle": KNOWN, "cup": None})
    assert placed[0].position[:2] == pytest.approx((3.0, 3.0))
    assert placed[1] is mug and placed[2] is tv



# --- a cut view as wide as the object is thick: an end, or a piece of its side ---------------------

SIDE_PIECE = (0.15, 0.42, 1.0)  # 0.42 m of a side along y, 0.15 m deep: 1.2 times the short side


@pytest.mark.parametrize("turn", [False, True], ids=["standing along y", "standing along x"])
@pytest.mark.parametrize("from_the_far_side", [False, True], ids=["from the east", "from the west"])
def test_a_cut_piece_of_a_known_objects_side_stays_on_it(turn, from_the_far_side) -> None:
    """A bicycle standing along y at (3.6, 5.2) is anchored at its middle; a cut view of 0.42 m of
    its east (or west) face, near its north end, reads by width alone as an end and would be placed
    0.7 m beyond the bicycle. The anchor says which side the camera faces: the piece stays on it."""
    middle, face_x = np.array((3.6, 5.2, 0.5)), 3.6 + 0.175 + 0.075
    viewpoint = np.array((6.0, 5.4, 1.0))
    if from_the_far_side:
        face_x, viewpoint = 3.6 - 0.175 - 0.075, np.array((1.2, 5.4, 1.0))
    centre, size = np.array((face_x, 5.7, 0.5)), np.array(SIDE_PIECE)
    if turn:
        middle, centre, size, viewpoint = middle[[1, 0, 2]], centre[[1, 0, 2]], size[[1, 0, 2]], viewpoint[[1, 0, 2]]
    piece = view(centre, size, viewpoint)
    assert long_axis_shown(size, KNOWN) is not None  # the width alone says "an end"
    placed = object_centre(piece, KNOWN, cut=True, nearby=[middle])
    sight = 1 if turn else 0
    assert abs(placed[sight] - middle[sight]) < 0.2  # on the bicycle, the side's reading
    alone = object_centre(piece, KNOWN, cut=True)
    assert abs(alone[sight] - middle[sight]) > 0.4  # no anchor to ask: the end's reading, 0.7 m beyond the face


def test_a_cut_end_beside_a_known_object_of_its_class_still_reads_as_an_end() -> None:
    """The east bicycle's south end, cut, seen from the south, with the west bicycle (0.65 m
    beside) anchored at its middle: the end's reading lands 0.65 m from that anchor, the side's
    farther, so the east one is placed at its own middle."""
    end = view((EAST[0], 5.85, 0.5), (0.36, 0.1, 1.0), (3.25, 4.0, 1.0))
    placed = object_centre(end, KNOWN, cut=True, nearby=[np.array((*WEST, 0.5))])
    assert placed[:2] == pytest.approx(EAST, abs=0.1)


def test_a_whole_view_as_wide_as_the_object_is_thick_is_its_end_whatever_stands_near() -> None:
    """Uncut, a box of that width cannot be a piece of the side (a whole side is as wide as the long
    side): it reads as an end even beside an anchor that the other reading would land on."""
    piece = view((3.85, 5.7, 0.5), SIDE_PIECE, (6.0, 5.4, 1.0))
    placed = object_centre(piece, KNOWN, cut=False, nearby=[np.array((3.6, 5.2, 0.5))])
    assert placed[0] == pytest.approx(3.85 - (1.6 - 0.15) / 2.0)


def test_placing_asks_each_views_own_cut_and_class_anchors() -> None:
    piece = view((3.85, 5.7, 0.5), SIDE_PIECE, (6.0, 5.4, 1.0))
    placed = placed_on_objects([piece, piece], {"bicycle": KNOWN}, cut=[True, False],
                               anchors_at={"bicycle": [np.array((3.6, 5.2, 0.5))], "tv": []})
    assert placed[0].position[0] == pytest.approx(3.85 - 0.1)  # half the short side less the depth seen
    assert placed[1].position[0] == pytest.approx(3.85 - 0.725)

# --- the parts rule: two ends side by side --------------------------------------------------------

@pytest.mark.parametrize("turn", [False, True], ids=["standing along y", "standing along x"])
def test_two_ends_side_by_side_are_not_parts_of_one_object_lying_across_them(turn) -> None:
    """The boxes of the run: the two bicycles' near ends, 0.68 m apart, never seen at one time; the
    box around both, 1.0 x 0.26 m, fits one bicycle lying across them."""
    west = bicycle("bicycle_5", 5.79, np.array((0.38, 0.15, 1.0)), first_seen=10.0, x=2.57, whole_views=4)
    east = bicycle("bicycle_7", 5.84, np.array((0.27, 0.26, 0.98)), first_seen=20.0, x=3.25, whole_views=3)
    known = bicycle("bicycle_1", 1.0, np.array((0.36, 1.68, 1.0)), first_seen=0.0, x=5.5, whole_views=30)
    anchors = [known, west, east]
    if turn:
        for anchor in anchors:
            anchor.position, anchor.size = anchor.position[[1, 0, 2]], anchor.size[[1, 0, 2]]
    assert decide(*anchors) == []


def test_an_end_and_the_whole_one_it_is_the_end_of_are_still_parts() -> None:
    whole_seen_elsewhere = seen_whole_elsewhere()
    end = bicycle("bicycle_2", 5.87, np.array((0.38, 0.15, 1.0)), first_seen=10.0)
    middle = bicycle("bicycle_3", 6.5, np.array((0.36, 0.9, 1.0)), first_seen=20.0)
    [parts] = decide(whole_seen_elsewhere, end, middle)
    assert (parts.kept.symbol, parts.part.symbol) == ("bicycle_2", "bicycle_3") and SLACK > 0


# --- frame by frame: two bicycles side by side, seen end-on, then one from its side ---------------

WEST, EAST = (2.6, 6.6), (3.25, 6.6)  # two bicycles standing along y, 0.65 m apart
DOORWAY = (3.0, 4.3, 1.0)  # south of both: each seen end-on, its near end at y = 5.8


def anchoring_that_knows_a_bicycle() -> tuple[Anchoring, PerceptMaker, float]:
    lifecycle = LifecycleConfig(confirm_after=2, missed_frames_to_missing=1, forget_after=600.0)
    anchoring = Anchoring(AnchoringConfig(lifecycle=lifecycle), matcher=RuleMatcher())
    maker = PerceptMaker(seed=3)
    whole = SceneObject("hall bicycle", "bicycle", (6.0, 1.0, 0.5), (0.35, 1.6, 1.0))
    stamp = 0.0
    for _ in range(4):
        percept = dataclasses.replace(maker.percept(whole, stamp, with_embedding=False),
                                      viewpoint=np.array((8.0, 1.0, 1.0)))
        anchoring.process([percept], None, stamp, partial=[False])
        stamp += 1.0 / 15.0
    return anchoring, maker, stamp


def seen(anchoring, maker, stamp, centre, size, viewpoint, frames: int = 4) -> tuple[float, list]:
    events = []
    for _ in range(frames):
        percept = maker.percept(SceneObject("b", "bicycle", centre, size), stamp, with_embedding=False)
        percept = dataclasses.replace(percept, viewpoint=np.array(viewpoint, dtype=float))
        events.extend(anchoring.process([percept], None, stamp, partial=[True]).events)
        stamp += 1.0 / 15.0
    return stamp, events


def test_two_bicycles_seen_end_on_keep_their_own_views_and_symbols() -> None:
    anchoring, maker, stamp = anchoring_that_knows_a_bicycle()
    end = (0.36, 0.05, 1.0)
    stamp, events = seen(anchoring, maker, stamp, (WEST[0], 5.82, 0.5), end, DOORWAY)
    west = anchoring.find(class_name="bicycle", near=np.array((*WEST, 0.5)))
    stamp += 5.0  # the robot turns away and back: the two ends are never in one frame
    stamp, more = seen(anchoring, maker, stamp, (EAST[0], 5.82, 0.5), end, DOORWAY)
    events += more
    east = anchoring.find(class_name="bicycle", near=np.array((*EAST, 0.5)))
    assert west.symbol != east.symbol
    assert np.linalg.norm(west.position[:2] - WEST) < 0.1 and np.linalg.norm(east.position[:2] - EAST) < 0.1
    stamp += 10.0  # then the east one's side, from the east, cut by a door frame
    stamp, more = seen(anchoring, maker, stamp, (3.43, 6.6, 0.5), (0.05, 1.2, 0.8), (5.0, 6.6, 1.0))
    events += more
    assert anchoring.get(east.symbol) is east and anchoring.get(west.symbol) is west
    assert east.last_seen > west.last_seen + 10.0  # the side went to its own bicycle
    assert np.linalg.norm(west.position[:2] - WEST) < 0.1  # and the west one's place is its own
    assert not [event for event in events if event.kind is AnchorEventKind.FORGOTTEN
                and event.symbol in (west.symbol, east.symbol)]



def test_a_known_bicycles_cut_side_pieces_stay_its_own_views() -> None:
    """Frame by frame through the core: the hall's bicycle known whole (standing along y at
    (6.0, 1.0)), then cut views of pieces of its east face, each as wide as the bicycle is thick,
    seen from the east and from the west: one anchor, no new one beside the bicycle (the rules
    forgive a view placed off its object along its length, not across it)."""
    anchoring, maker, stamp = anchoring_that_knows_a_bicycle()
    [known] = anchoring.anchors
    events = []
    for face_x, viewpoint in ((6.25, (8.0, 1.2, 1.0)), (5.75, (4.0, 1.2, 1.0))):  # its east face, its west face
        for piece_y in (1.0, 0.6):  # read as an end, placed 0.48 m off the bicycle across its short side
            stamp, more = seen(anchoring, maker, stamp, (face_x, piece_y, 0.5), SIDE_PIECE, viewpoint)
            events += more
            stamp += 1.0
    assert [anchor.symbol for anchor in anchoring.anchors] == [known.symbol]
    assert not [event for event in events if event.kind is AnchorEventKind.ACQUIRED]
