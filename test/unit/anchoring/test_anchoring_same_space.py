"""A missing anchor in the very space of an anchor of its class seen there is a second anchor of that object.

The case comes from the scenario suite: seven books 2 cm apart, percepts sliding while the robot
drove, left one book with a second anchor, MISSING on the spot where the first is seen (both
matchers), and the long search of `removed` left birds, cats and books the same way. Tested
below on a detector that reports one mug twice for a while, then on the rules' limits: two books
side by side, a mug of another colour in a lost mug's place, a pair that never stood together, a
sought anchor, and which symbol stays. Then a missing anchor born of a box drawn across two
books, whose space the two fill (`twin_removed_from_the_shelf`, network, seed 2), against a removed
book between its neighbours and the parts of one object.
"""

from __future__ import annotations

import numpy as np
import pytest

from merlin2_sailor.anchoring import AnchorEventKind, Anchoring, AnchoringConfig, AnchorState, Expectation
from merlin2_sailor.anchoring.anchor import Anchor
from merlin2_sailor.anchoring.anchor_index import AnchorIndex
from merlin2_sailor.anchoring.colour_evidence import ColourEvidenceConfig, ColourModel
from merlin2_sailor.anchoring.gallery import to_bfloat16_bits
from merlin2_sailor.anchoring.identity_repair import Merge, RepairConfig
from merlin2_sailor.anchoring.lifecycle import LifecycleConfig
from merlin2_sailor.anchoring.same_space import Duplicate, decide_same_space, shared_volume
from merlin2_sailor.errors import ConfigurationError

from .anchoring_scenes import PerceptMaker, SceneObject, camera_view, mug_colour

FRAME = 1.0 / 15.0
RED, GREEN = 17, 6
BOOK_SIZE = np.array((0.16, 0.04, 0.24))
COLOUR = ColourEvidenceConfig()


def book(symbol: str, x: float, state: AnchorState, first_seen: float, last_seen: float, hue: int | None = None):
    anchor = Anchor(symbol, "book", np.array((x, 2.0, 1.0)), BOOK_SIZE.copy(), first_seen, last_seen, state=state,
                    perceived_position=np.array((x, 2.0, 1.0)))
    anchor.visible = state is AnchorState.CONFIRMED
    if hue is not None:
        anchor.colour = ColourModel.of(mug_colour(hue))
        for _ in range(4):
            anchor.colour.add(mug_colour(hue))
    return anchor


def decide(*anchors: Anchor, overlap: float = 0.5):
    index = AnchorIndex()
    for anchor in anchors:
        index.add(anchor)
    seen = [anchor for anchor in anchors if anchor.visible]
    return decide_same_space(seen, index, overlap, COLOUR)


def test_a_detector_reporting_one_mug_twice_leaves_one_anchor_once_the_double_is_gone():
    maker = PerceptMaker(seed=3)
    lifecycle = LifecycleConfig(confirm_after=2, missed_frames_to_missing=1, forget_after=600.0)
    anchoring = Anchoring(AnchoringConfig(lifecycle=lifecycle))
    mug = SceneObject("mug", "cup", (2.5, 0.0, 0.8))
    double = SceneObject("mug", "cup", (2.5, 0.04, 0.8))
    stamp, events = 0.0, []
    for frame in range(20):
        items = [mug, double] if 3 <= frame < 8 else [mug]
        result = anchoring.process([maker.percept(item, stamp) for item in items], camera_view(), stamp)
        events.extend(result.events)
        stamp += FRAME
    assert [(a.symbol, a.state) for a in anchoring.anchors] == [("cup_1", AnchorState.CONFIRMED)]
    gone = [e for e in events if e.kind is AnchorEventKind.FORGOTTEN]
    assert len(gone) == 1 and gone[0].symbol == "cup_2"
    assert gone[0].details["reason"].startswith("in the same space as cup_1")


def test_the_younger_missing_anchor_goes_and_an_older_missing_one_takes_the_seen_one_over():
    older_missing = book("book_1", 2.00, AnchorState.MISSING, 0.0, 50.0)
    seen = book("book_9", 2.03, AnchorState.CONFIRMED, 40.0, 60.0)
    [merge] = decide(older_missing, seen)
    assert isinstance(merge, Merge) and (merge.kept, merge.merged) == (older_missing, seen)

    younger_missing = book("book_9", 2.03, AnchorState.MISSING, 40.0, 50.0)
    seen = book("book_1", 2.00, AnchorState.CONFIRMED, 0.0, 60.0)
    [duplicate] = decide(younger_missing, seen)
    assert isinstance(duplicate, Duplicate) and (duplicate.kept, duplicate.duplicate) == (seen, younger_missing)
    assert duplicate.overlap == pytest.approx(shared_volume(seen, younger_missing))


def test_two_books_side_by_side_are_two_books():
    """18 cm between centres, 16 cm wide: the boxes do not meet."""
    assert decide(book("book_1", 2.00, AnchorState.MISSING, 0.0, 50.0),
                  book("book_2", 2.18, AnchorState.CONFIRMED, 0.0, 60.0)) == []


def test_an_anchor_of_another_colour_in_a_lost_ones_place_is_another_object():
    """The swap: the green book put where the red one stood."""
    assert decide(book("book_1", 2.00, AnchorState.MISSING, 0.0, 50.0, hue=RED),
                  book("book_2", 2.01, AnchorState.CONFIRMED, 40.0, 60.0, hue=GREEN)) == []
    assert len(decide(book("book_1", 2.00, AnchorState.MISSING, 0.0, 50.0, hue=RED),
                      book("book_2", 2.01, AnchorState.CONFIRMED, 40.0, 60.0, hue=RED))) == 1


def box(symbol: str, class_name: str, centre: tuple[float, float], size: tuple[float, float, float],
        state: AnchorState, first_seen: float, last_seen: float) -> Anchor:
    anchor = book(symbol, centre[0], state, first_seen, last_seen)
    anchor.class_name, anchor.size = class_name, np.array(size)
    anchor.position[:2] = anchor.perceived_position[:2] = centre
    return anchor


@pytest.mark.parametrize(("class_name", "across", "held", "size"), [
    # a box across two bicycles side by side 0.65 m apart, seen end-on; the other's end inside it
    ("bicycle", (2.9, 5.85), (3.24, 6.0), (0.35, 0.3, 1.0)),
    # across two books of a shelf; the right one's anchor inside it, near its edge
    ("book", (2.0, 2.0), (2.09, 2.0), (0.16, 0.04, 0.24)),
    # across a row of three mugs; the middle one's anchor beside its centre, the first one's
    ("cup", (1.0, 0.0), (0.92, 0.02), (0.09, 0.09, 0.11)),
])
def test_a_small_anchor_inside_a_box_drawn_across_two_objects_is_not_one_space_with_it(
    class_name, across, held, size,
):
    """The smaller box shares all its volume with the larger, but neither's centre lies in the
    other's footprint: a box across two objects holds one of them, it is not the same space."""
    wide = (float(size[0]) * 3.0, float(size[1]) * 2.0, float(size[2]))
    seen_across = box(f"{class_name}_1", class_name, across, wide, AnchorState.CONFIRMED, 0.0, 60.0)
    missing = box(f"{class_name}_2", class_name, held, size, AnchorState.MISSING, 10.0, 50.0)
    assert shared_volume(seen_across, missing) > 0.7
    assert decide(seen_across, missing) == []
    missing.position[:2] = across  # the same box on the wide one's centre: one space
    assert len(decide(seen_across, missing)) == 1


def test_a_pair_that_never_stood_together_is_left_to_the_reappearance_rules():
    """Born after the missing one's last sighting: perhaps another book put in its place."""
    assert decide(book("book_1", 2.00, AnchorState.MISSING, 0.0, 30.0),
                  book("book_2", 2.01, AnchorState.CONFIRMED, 40.0, 60.0)) == []


def test_a_sought_anchor_and_an_anchor_of_another_class_are_left_alone():
    sought = book("book_1", 2.00, AnchorState.MISSING, 0.0, 50.0)
    sought.expectation = Expectation.at(sought.position, 55.0, "living_room", "find", radius=1.0)
    assert decide(sought, book("book_2", 2.01, AnchorState.CONFIRMED, 0.0, 60.0)) == []
    vase = book("vase_1", 2.01, AnchorState.CONFIRMED, 0.0, 60.0)
    vase.class_name = "vase"
    assert decide(book("book_1", 2.00, AnchorState.MISSING, 0.0, 50.0), vase) == []


@pytest.mark.parametrize(("offset", "shared"), [(0.0, 1.0), (0.04, 0.75), (0.08, 0.5), (0.16, 0.0), (0.3, 0.0)])
def test_shared_volume_is_the_share_of_the_smaller_box(offset, shared):
    first = book("book_1", 2.0, AnchorState.MISSING, 0.0, 1.0)
    second = book("book_2", 2.0 + offset, AnchorState.CONFIRMED, 0.0, 1.0)
    assert shared_volume(first, second) == pytest.approx(shared)
    second.size = BOOK_SIZE / 2.0
    second.position = first.position.copy()
    assert shared_volume(first, second) == pytest.approx(1.0)


def test_the_rule_can_be_turned_off_and_is_checked():
    assert decide(book("book_1", 2.00, AnchorState.MISSING, 0.0, 50.0),
                  book("book_2", 2.01, AnchorState.CONFIRMED, 0.0, 60.0), overlap=0.0) == []
    with pytest.raises(ConfigurationError, match="same_space_overlap"):
        RepairConfig(same_space_overlap=1.5)


def test_an_appearance_matcher_must_also_take_one_for_the_other():
    # A red book's anchor slid onto its blue neighbour's missing one, neither colour known (seen
    # from afar): overlap and colour allow the merge; the look rules it out.
    from .anchoring_scenes import AppearanceRules

    maker = PerceptMaker(seed=5)
    red, blue = maker.appearance("red_book"), maker.appearance("blue_book")
    older_missing = book("book_3", 2.00, AnchorState.MISSING, 0.0, 50.0)
    seen = book("book_8", 2.03, AnchorState.CONFIRMED, 40.0, 60.0)
    for anchor, look in ((older_missing, blue), (seen, red)):
        anchor.gallery = to_bfloat16_bits(look.reshape(1, -1))
    index = AnchorIndex()
    for anchor in (older_missing, seen):
        index.add(anchor)
    assert decide_same_space([seen], index, 0.5, COLOUR) != []  # the rules' judgement: one object
    assert decide_same_space([seen], index, 0.5, COLOUR, AppearanceRules(), 0.5) == []

    seen.gallery = to_bfloat16_bits(blue.reshape(1, -1))  # the same look: one object, as before
    [merge] = decide_same_space([seen], index, 0.5, COLOUR, AppearanceRules(), 0.5)
    assert isinstance(merge, Merge) and merge.kept is older_missing


# A box drawn across two objects: the anchor it left is no object's.

def strongly(hue: int) -> np.ndarray:
    """A book's colour, 40 % of its pixels in its own hue."""
    return mug_colour(hue, 0.4)


BLEND = (strongly(RED) + strongly(GREEN)) / 2.0


def coloured(anchor: Anchor, histogram: np.ndarray) -> Anchor:
    anchor.colour = ColourModel.of(histogram)
    for _ in range(4):
        anchor.colour.add(histogram)
    return anchor


def wide_book(symbol: str, x: float, state: AnchorState, first_seen: float, last_seen: float) -> Anchor:
    """An anchor of a box across two books standing side by side at x - 0.09 and x + 0.09: its
    colour blends theirs."""
    anchor = coloured(book(symbol, x, state, first_seen, last_seen), BLEND)
    anchor.size = np.array((0.34, 0.04, 0.24))
    return anchor


def shelf_book(symbol: str, x: float, first_seen: float, hue: int) -> Anchor:
    return coloured(book(symbol, x, AnchorState.CONFIRMED, first_seen, 60.0), strongly(hue))


def seen_together(*anchors: Anchor) -> tuple[Anchor, ...]:
    for anchor in anchors:
        anchor.seen_with.update(other.symbol for other in anchors if other is not anchor)
    return anchors


def test_a_missing_anchor_whose_space_two_books_seen_at_one_time_fill_is_forgotten():
    left, right = seen_together(shelf_book("book_1", 1.91, 0.0, RED), shelf_book("book_2", 2.09, 0.0, GREEN))
    across = wide_book("book_3", 2.0, AnchorState.MISSING, 10.0, 20.0)
    assert decide(left, across) == [] and decide(right, across) == []  # each alone: another colour
    [duplicate] = decide(left, right, across)
    assert isinstance(duplicate, Duplicate) and duplicate.duplicate is across
    assert duplicate.kept in (left, right)
    assert duplicate.reason.startswith("a box across")
    assert duplicate.explanation.endswith("not an object of its own")


def test_parts_of_one_object_never_seen_at_one_time_leave_the_whole_ones_anchor_alone():
    """Two views of one long object's ends, each in its own frames, inside its missing anchor."""
    left, right = shelf_book("book_1", 1.91, 0.0, RED), shelf_book("book_2", 2.09, 0.0, GREEN)
    across = wide_book("book_3", 2.0, AnchorState.MISSING, 10.0, 20.0)
    assert decide(left, right, across) == []


def test_a_removed_book_between_two_seen_neighbours_keeps_its_anchor():
    """Its box, as large as theirs, only grazes them: the space is empty, not filled by them."""
    left, right = seen_together(shelf_book("book_1", 1.83, 0.0, RED), shelf_book("book_3", 2.17, 0.0, GREEN))
    removed = coloured(book("book_2", 2.0, AnchorState.MISSING, 0.0, 30.0), strongly(RED))
    assert decide(left, right, removed) == []
    removed.size = np.array((0.2, 0.04, 0.24))  # boxes a little too large: still a book of its own
    assert decide(left, right, removed) == []


def test_one_anchor_inside_a_larger_missing_one_is_the_pairwise_rules_not_this_ones():
    """One book seen inside a wider missing anchor of another colour: no evidence of two objects."""
    [single] = seen_together(shelf_book("book_1", 1.91, 0.0, GREEN))
    assert decide(single, wide_book("book_3", 2.0, AnchorState.MISSING, 10.0, 20.0)) == []


def test_a_sought_anchor_or_one_never_seen_with_the_two_is_left_alone():
    left, right = seen_together(shelf_book("book_1", 1.91, 30.0, RED), shelf_book("book_2", 2.09, 30.0, GREEN))
    earlier = wide_book("book_3", 2.0, AnchorState.MISSING, 0.0, 20.0)  # lost before they came
    assert decide(left, right, earlier) == []
    sought = wide_book("book_3", 2.0, AnchorState.MISSING, 10.0, 40.0)
    sought.expectation = Expectation.at(sought.position, 55.0, "living_room", "find", radius=1.0)
    assert decide(left, right, sought) == []


def test_a_detector_drawing_one_box_across_two_books_for_a_while_leaves_two_anchors():
    maker = PerceptMaker(seed=11)
    lifecycle = LifecycleConfig(confirm_after=2, missed_frames_to_missing=1, forget_after=600.0)
    anchoring = Anchoring(AnchoringConfig(lifecycle=lifecycle))
    red = SceneObject("red", "book", (2.5, -0.09, 0.8), size=(0.04, 0.16, 0.24), colour=strongly(RED))
    green = SceneObject("green", "book", (2.5, 0.09, 0.8), size=(0.04, 0.16, 0.24), colour=strongly(GREEN))
    across = SceneObject("across", "book", (2.5, 0.0, 0.8), size=(0.04, 0.34, 0.24), colour=BLEND)
    stamp, events = 0.0, []
    for frame in range(30):
        items = [red, green, across] if 8 <= frame < 14 else [red, green]
        result = anchoring.process([maker.percept(item, stamp) for item in items], camera_view(), stamp)
        events.extend(result.events)
        stamp += FRAME
    assert [a.state for a in anchoring.anchors] == [AnchorState.CONFIRMED] * 2
    [gone] = [e for e in events if e.kind is AnchorEventKind.FORGOTTEN]
    assert gone.details["reason"].startswith("a box across")
