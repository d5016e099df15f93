"""Anchors of a large object seen in pieces are joined into one; two objects never are.

The case comes from the scenario suite: a bicycle wheeled into another room was seen there only
in parts (a wheel, its middle, its far end), each part anchored anew, three confirmed anchors of
one bicycle. Tested on a bicycle seen whole once and then in parts elsewhere, on parts joined
step by step, and on what must stay two objects: two bicycles side by side or end to end, parts
seen at one time, another colour, no whole one ever seen, small objects, and a box built from
parts taken as the extent of its class.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from merlin2_sailor.anchoring import AnchorEventKind, Anchoring, AnchoringConfig, AnchorState, colour_evidence
from merlin2_sailor.anchoring.anchor import Anchor
from merlin2_sailor.anchoring.anchor_comparison import looks_compared, score_anywhere
from merlin2_sailor.anchoring.anchor_index import AnchorIndex
from merlin2_sailor.anchoring.colour_evidence import ColourEvidenceConfig, ColourModel, with_view
from merlin2_sailor.anchoring.expectation import Expectation
from merlin2_sailor.anchoring.frame_changes import FrameChanges
from merlin2_sailor.anchoring.gallery import add_view
from merlin2_sailor.anchoring.identity_repair import RepairConfig
from merlin2_sailor.anchoring.lifecycle import LifecycleConfig
from merlin2_sailor.anchoring.merge import join_parts
from merlin2_sailor.anchoring.parts import Parts, decide_parts, largest_seen_whole, seen_whole_at_last
from merlin2_sailor.anchoring.snapshot import anchor_from_dict, anchor_to_dict, anchors_of_snapshot
from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.perception.colour_histogram import COLOUR_BINS, HUE_BINS

from .anchoring_scenes import AppearanceRules, PerceptMaker, SceneObject, mug_colour

FRAME = 1.0 / 15.0
BICYCLE = np.array((0.35, 1.6, 1.0))
PART = np.array((0.35, 0.45, 1.0))
COLOUR = ColourEvidenceConfig()
SLACK = RepairConfig().part_slack


def bicycle(symbol: str, y: float, size: np.ndarray = PART, first_seen: float = 10.0, x: float = 3.0,
            state: AnchorState = AnchorState.CONFIRMED, whole_views: int = 0, hue: int | None = None) -> Anchor:
    position = np.array((x, y, 0.5))
    anchor = Anchor(symbol, "bicycle", position, np.asarray(size, dtype=np.float64).copy(), first_seen,
                    first_seen + 1.0, state=state, whole_views=whole_views, perceived_position=position.copy(),
                    class_votes={"bicycle": 3.0})
    anchor.visible = state is AnchorState.CONFIRMED
    if hue is not None:
        anchor.colour = ColourModel.of(mug_colour(hue, share=0.6))
        for _ in range(4):
            anchor.colour.add(mug_colour(hue, share=0.6))
    return anchor


def seen_whole_elsewhere(symbol: str = "bicycle_1") -> Anchor:
    """The bicycle as the robot knew it before it was moved: seen whole, many times, now missing."""
    return bicycle(symbol, -5.0, BICYCLE, first_seen=0.0, state=AnchorState.MISSING, whole_views=20)


def decide(*anchors: Anchor, slack: float = SLACK) -> list[Parts]:
    index = AnchorIndex()
    for anchor in anchors:
        index.add(anchor)
    return decide_parts([anchor for anchor in anchors if anchor.visible], index, slack, COLOUR)


def test_two_parts_inside_one_bicycle_are_joined_into_the_older_with_the_box_around_both():
    front = bicycle("bicycle_2", 3.40, first_seen=10.0)
    rear = bicycle("bicycle_3", 4.55, first_seen=20.0)
    [parts] = decide(seen_whole_elsewhere(), front, rear)
    assert (parts.kept, parts.part) == (front, rear)
    np.testing.assert_allclose(parts.high - parts.low, (0.35, 1.6, 1.0), atol=1e-9)
    np.testing.assert_allclose(parts.known, (1.6, 0.35, 1.0))
    assert "parts of one bicycle" in parts.reason


def test_a_part_beside_a_whole_view_of_the_same_size_is_joined_and_the_whole_box_is_the_object():
    """A whole television, and a part of it anchored anew past a door frame."""
    whole = bicycle("bicycle_2", 4.0, BICYCLE, first_seen=10.0, whole_views=6)
    part = bicycle("bicycle_3", 4.5, first_seen=20.0)
    [parts] = decide(whole, part)
    assert (parts.kept, parts.part) == (whole, part)


def test_a_box_joined_from_parts_takes_a_larger_piece_and_keeps_only_the_larger_pieces_views():
    """A box already joined from parts counts as a part (its views are the parts'), so a larger
    piece seen later, itself too large to be called a part, joins it: the box and the appearance
    views are the larger piece's; the joined box's views, of parts, are dropped."""
    def with_views(anchor: Anchor, count: int) -> Anchor:
        for view in np.random.default_rng(count).normal(size=(count, 8)):
            anchor.gallery, anchor.gallery_scales = add_view(anchor.gallery, anchor.gallery_scales,
                                                             view.astype(np.float32), 40.0, 10)
        return anchor

    joined = with_views(bicycle("bicycle_2", 4.20, np.array((0.35, 1.0, 1.0)), first_seen=10.0, whole_views=2), 3)
    joined.parts_fit = BICYCLE[[1, 0, 2]] * (1.0 + SLACK)
    larger = with_views(bicycle("bicycle_3", 4.45, np.array((0.35, 1.1, 1.0)), first_seen=20.0, whole_views=3), 2)
    larger_views = larger.gallery.copy()
    [parts] = decide(seen_whole_elsewhere(), joined, larger)
    assert (parts.kept, parts.part) == (joined, larger)
    index = AnchorIndex()
    for anchor in (joined, larger):
        index.add(anchor)
    join_parts(parts, index, FrameChanges(30.0), AnchoringConfig().fusion)
    assert "bicycle_3" not in index and joined.state is AnchorState.CONFIRMED
    np.testing.assert_array_equal(joined.gallery, larger_views)
    low, high = joined.position - joined.size / 2, joined.position + joined.size / 2
    assert (low[1], high[1]) == pytest.approx((3.90, 5.00))
    assert joined.parts_fit is None and joined.whole_views == 3  # the larger piece's, seen whole


@pytest.mark.parametrize(("whole_y", "whole_length", "part_y", "expected"), [
    # The wheeled bicycle's near end, seen from the hall with nothing cut: 1.23 m of 1.6, centred
    # 0.5 m short of the middle; then its far end (scenario suite, seed 1, 6 December 2026).
    (4.64, 1.23, 5.76, (4.025, 5.985)),
    # The same the other way round, the far end seen first and long.
    (6.0, 1.1, 5.0, (4.775, 6.55)),
    # A part inside the whole one's box is noise of it: the whole box stays.
    (4.64, 1.23, 4.9, (4.025, 5.255)),
])
def test_a_part_beyond_a_whole_ones_box_widens_it_to_the_box_around_both(whole_y, whole_length, part_y, expected):
    """A view over ``PARTIAL_FOOTPRINT_SHARE`` of the whole one's footprint is no part, yet may
    miss a quarter of the object: a part of the object seen beyond its box shows the object reaches
    there. The joined anchor then holds the box around both, as a box of parts."""
    longer = bicycle("bicycle_2", whole_y, np.array((0.38, whole_length, 0.95)), first_seen=10.0, whole_views=8)
    part = bicycle("bicycle_3", part_y, np.array((0.35, 0.45, 1.0)), first_seen=20.0)
    [parts] = decide(seen_whole_elsewhere(), longer, part)
    index = AnchorIndex()
    for anchor in (longer, part):
        index.add(anchor)
    join_parts(parts, index, FrameChanges(30.0), AnchoringConfig().fusion)
    low, high = longer.position - longer.size / 2, longer.position + longer.size / 2
    assert (low[1], high[1]) == pytest.approx(expected)
    assert "bicycle_3" not in index and longer.state is AnchorState.CONFIRMED
    assert (longer.parts_fit is None) == (expected == pytest.approx((whole_y - whole_length / 2,
                                                                     whole_y + whole_length / 2)))


@pytest.mark.parametrize(
    "second, why",
    [
        (bicycle("bicycle_3", 5.40, first_seen=20.0), "end to end: the box around both is 2.45 m"),
        (bicycle("bicycle_3", 3.40, first_seen=20.0, x=3.6), "side by side: 0.95 m wide"),
        (bicycle("bicycle_3", 3.90, BICYCLE, first_seen=20.0, whole_views=5, x=3.5), "a whole one beside it"),
    ],
)
def test_two_bicycles_are_never_joined(second: Anchor, why: str):
    first = bicycle("bicycle_2", 3.40, first_seen=10.0)
    assert decide(seen_whole_elsewhere(), first, second) == [], why


def _turned(anchor: Anchor) -> Anchor:
    """The same anchor with the house turned a quarter: x and y swapped."""
    anchor.position = anchor.position[[1, 0, 2]]
    anchor.perceived_position = anchor.position.copy()
    anchor.size = anchor.size[[1, 0, 2]]
    return anchor


def _wheeled_bicycle_seen_from_two_sides(far_end_x: float) -> tuple[Anchor, Anchor, Anchor]:
    """The anchors of `large_object_wheeled_away`, seed 2 (7 December 2026), read from the run's
    final snapshot: the bicycle where it stood (53 whole views), a box joined from its near end's
    parts, and its far end seen from the other side, a narrow box across, shifted sideways."""
    known = bicycle("bicycle_1", 6.99, np.array((0.36, 1.68, 1.0)), first_seen=0.0,
                    state=AnchorState.MISSING, whole_views=53, x=5.76)
    near = bicycle("bicycle_3", 4.81, np.array((0.40, 0.85, 0.84)), first_seen=10.0, whole_views=2, x=3.59)
    near.parts_fit = np.array((2.10, 0.45, 1.25))
    far = bicycle("bicycle_7", 5.80, np.array((0.13, 0.46, 1.0)), first_seen=20.0,
                  state=AnchorState.MISSING, whole_views=2, x=far_end_x)
    return known, near, far


@pytest.mark.parametrize("turn", [False, True], ids=["along y", "along x"])
@pytest.mark.parametrize("far_end_x", [3.78, 3.40, 3.59, 3.80, 3.37],
                         ids=["shifted", "shifted the other way", "in line", "centre just past its side",
                              "centre just past its other side"])
def test_parts_seen_from_two_sides_are_joined_though_their_boxes_are_shifted_across(far_end_x, turn):
    """Their box around both is 0.455-0.475 m wide where one bicycle is 0.36 m (0.45 with the
    slack); but the far end's box shares some of the near end's width, its centre within it or
    just past its side: one object that wide."""
    anchors = _wheeled_bicycle_seen_from_two_sides(far_end_x)
    if turn:
        anchors = tuple(_turned(anchor) for anchor in anchors)
    [parts] = decide(*anchors)
    assert (parts.kept.symbol, parts.part.symbol) == ("bicycle_3", "bicycle_7")


@pytest.mark.parametrize("turn", [False, True], ids=["along y", "along x"])
@pytest.mark.parametrize("far_end_x", [3.87, 3.31, 4.20], ids=["beside", "beside the other way", "farther"])
def test_boxes_clear_of_each_other_across_are_not_one_object(far_end_x, turn):
    """The same boxes with the narrow one clear of the wide one's side (by 0.015 m and more), as two
    objects side by side stand: the box around both must fit, and at 0.545 m wide and more it does
    not."""
    anchors = _wheeled_bicycle_seen_from_two_sides(far_end_x)
    if turn:
        anchors = tuple(_turned(anchor) for anchor in anchors)
    assert decide(*anchors) == []


PART_BESIDE_ITS_WHOLE = Path(__file__).parent / "data" / "bicycle_part_beside_its_whole.json"


@pytest.mark.parametrize("turn", [False, True], ids=["along y", "along x"])
def test_the_suites_part_reaching_past_its_bicycles_side_is_joined_and_the_bicycle_keeps_its_width(turn):
    """The run's own anchors (`moved_to_the_far_room`, network, seed 0, 7 December 2026, the final
    snapshot): a part of the hall's bicycle seen first (0.15 x 0.84 m, its box reaching 0.125 m past
    the bicycle's side, its centre 0.05 m beyond the whole box's width) and the bicycle seen whole
    88 times (0.36 x 1.65 m). The box around both is 0.485 m wide against the 0.45 m one bicycle
    may fill, so the run kept two anchors of it; their boxes share 0.03 m of width, so they are one
    bicycle, kept under the older symbol on the whole one's box, not widened by the part's error."""
    snapshot = json.loads(PART_BESIDE_ITS_WHOLE.read_text())
    anchors, _ = anchors_of_snapshot(snapshot, snapshot["world_frame"])
    if turn:
        anchors = [_turned(anchor) for anchor in anchors]
    part, whole = sorted(anchors, key=lambda anchor: anchor.symbol)
    assert (part.symbol, whole.symbol, part.whole_views, whole.whole_views) == ("bicycle_1", "bicycle_3", 1, 88)
    whole_box = (whole.position.copy(), whole.size.copy())
    for anchor in anchors:
        anchor.visible = True
    [parts] = decide(part, whole)
    assert (parts.kept, parts.part) == (part, whole)
    index = AnchorIndex()
    for anchor in anchors:
        index.add(anchor)
    join_parts(parts, index, FrameChanges(whole.last_seen), AnchoringConfig().fusion)
    assert "bicycle_3" not in index and part.state is AnchorState.CONFIRMED
    np.testing.assert_allclose(part.position, whole_box[0])
    np.testing.assert_allclose(part.size, whole_box[1])


def test_parts_seen_at_one_time_are_two_objects():
    front = bicycle("bicycle_2", 3.40, first_seen=10.0)
    rear = bicycle("bicycle_3", 4.55, first_seen=20.0)
    front.seen_with.add("bicycle_3")
    assert decide(seen_whole_elsewhere(), front, rear) == []


def test_no_join_without_a_whole_one_of_the_class_seen_or_with_the_rule_off():
    front = bicycle("bicycle_2", 3.40, first_seen=10.0)
    rear = bicycle("bicycle_3", 4.55, first_seen=20.0)
    assert decide(front, rear) == []  # how large is a bicycle? nothing seen says
    once = seen_whole_elsewhere()
    once.whole_views = 1  # one box may be a detector's slip around two neighbours
    assert decide(once, front, rear) == []
    assert decide(seen_whole_elsewhere(), front, rear, slack=0.0) == []


def test_a_box_built_from_parts_is_not_the_extent_of_its_class_but_the_whole_one_it_was_fit_in_is():
    """Its box (2.0 m, as wide as the slack let it grow) does not count; the 1.6 m bicycle its parts
    were fit in does, though no anchor holds that bicycle's box any more (a search merged the joined
    anchor into the one it sought, which took the joined box)."""
    joined = bicycle("bicycle_2", 0.0, np.array((0.35, 2.0, 1.0)), first_seen=1.0, whole_views=2)
    joined.parts_fit = BICYCLE[[1, 0, 2]] * (1.0 + SLACK)
    index = AnchorIndex()
    index.add(joined)
    np.testing.assert_allclose(largest_seen_whole(index, "bicycle", SLACK), (1.6, 0.35, 1.0))
    front = bicycle("bicycle_3", 3.40, first_seen=10.0)
    assert decide(joined, front, bicycle("bicycle_4", 5.20, first_seen=20.0)) == []  # 2.25 m: too long
    [parts] = decide(joined, front, bicycle("bicycle_4", 4.55, first_seen=20.0))
    assert parts.kept is front


def bicycle_colour(frame_hue: int, frame: float, tyres: float, rng: np.random.Generator) -> np.ndarray:
    """A bicycle's colour as a view shows it: ``frame`` of the pixels in its frame's hue bin,
    ``tyres`` in dark grey, the rest light grey, each share a little off from view to view."""
    histogram = np.zeros(COLOUR_BINS)
    histogram[frame_hue], histogram[HUE_BINS] = frame, tyres
    histogram[HUE_BINS + 2] = 1.0 - frame - tyres
    histogram = np.clip(histogram + rng.normal(0.0, 0.01, COLOUR_BINS) * (histogram > 0), 0.0, None)
    return histogram / histogram.sum()


def coloured(anchor: Anchor, frame_hue: int, frame: float, tyres: float, views: int) -> Anchor:
    rng = np.random.default_rng(views + frame_hue)
    for _ in range(views):
        anchor.colour = with_view(anchor.colour, bicycle_colour(frame_hue, frame, tyres, rng))
    return anchor


@pytest.mark.parametrize(("part_hue", "frame", "tyres", "joined"), [
    (1, 0.25, 0.45, True),   # a wheel: twice the whole's black, half its orange
    (1, 0.15, 0.20, True),   # a part showing more of the light grey mudguards
    (1, 0.65, 0.10, True),   # the frame up close: more orange, less black
    (8, 0.30, 0.40, False),  # a blue bicycle's part: a colour the orange one lacks
    (13, 0.20, 0.20, False),  # a purple one's
])
def test_a_part_beside_a_whole_one_is_held_only_to_showing_no_colour_the_whole_lacks(part_hue, frame, tyres,
                                                                                     joined):
    """A part shows some of its object's faces, so its colours come in other shares than the whole
    one's, by more than two anchors of one object may differ; what it cannot show is a colour the
    object lacks."""
    whole = coloured(bicycle("bicycle_2", 4.0, BICYCLE, first_seen=10.0, whole_views=6), 1, 0.45, 0.20, views=6)
    part = coloured(bicycle("bicycle_3", 4.5, first_seen=20.0), part_hue, frame, tyres, views=2)
    if joined:
        assert colour_evidence.anchor_colours_differ(part, whole, COLOUR)  # as any two anchors, they differ
        [parts] = decide(whole, part)
        assert (parts.kept, parts.part) == (whole, part)
    else:
        assert decide(whole, part) == []


def test_a_parts_colour_is_evidence_only_where_one_of_the_two_knows_its_colour():
    whole = coloured(bicycle("bicycle_2", 4.0, BICYCLE, first_seen=10.0, whole_views=6), 1, 0.45, 0.20, views=2)
    part = coloured(bicycle("bicycle_3", 4.5, first_seen=20.0), 8, 0.30, 0.40, views=2)
    assert not colour_evidence.part_shows_a_colour_the_whole_lacks(part, whole, COLOUR)
    assert colour_evidence.part_shows_a_colour_the_whole_lacks(coloured(part, 8, 0.30, 0.40, views=1), whole, COLOUR)
    assert colour_evidence.part_shows_a_colour_the_whole_lacks(part, coloured(whole, 1, 0.45, 0.20, views=1), COLOUR)
    assert not colour_evidence.part_shows_a_colour_the_whole_lacks(whole, part, ColourEvidenceConfig(minimum_views=0))


def test_other_colours_an_expected_anchor_and_tentative_ones_are_left_alone():
    red = bicycle("bicycle_2", 3.40, first_seen=10.0, hue=1)
    blue = bicycle("bicycle_3", 4.55, first_seen=20.0, hue=8)
    assert decide(seen_whole_elsewhere(), red, blue) == []
    carried = bicycle("bicycle_2", 3.40, first_seen=10.0)
    carried.expectation = Expectation.at(np.array((3.0, 3.4, 0.5)), 5.0, source="bring")
    assert decide(seen_whole_elsewhere(), carried, bicycle("bicycle_3", 4.55, first_seen=20.0)) == []
    tentative = bicycle("bicycle_3", 4.55, first_seen=20.0, state=AnchorState.TENTATIVE)
    assert decide(seen_whole_elsewhere(), bicycle("bicycle_2", 3.40, first_seen=10.0), tentative) == []


def test_small_objects_are_never_joined_as_parts():
    def mug(symbol: str, y: float, first_seen: float, whole_views: int = 0) -> Anchor:
        anchor = bicycle(symbol, y, np.array((0.1, 0.1, 0.11)), first_seen=first_seen, whole_views=whole_views)
        anchor.class_name = "cup"
        return anchor

    assert decide(mug("cup_1", 0.0, 0.0, whole_views=9), mug("cup_2", 3.0, 10.0), mug("cup_3", 3.05, 20.0)) == []


def test_the_setting_is_checked():
    with pytest.raises(ConfigurationError, match="part_slack"):
        RepairConfig(part_slack=-0.1)
    with pytest.raises(ConfigurationError, match="part_slack"):
        RepairConfig(part_slack=1.5)


def test_what_was_seen_together_and_the_box_from_parts_survive_a_restart():
    anchor = bicycle("bicycle_2", 3.4)
    anchor.seen_with = {"bicycle_5", "bicycle_9"}
    anchor.parts_fit = np.array((2.0, 0.44, 1.25))
    restored = anchor_from_dict(anchor_to_dict(anchor))
    assert restored.seen_with == {"bicycle_5", "bicycle_9"}
    np.testing.assert_allclose(restored.parts_fit, (2.0, 0.44, 1.25))
    assert anchor_from_dict(anchor_to_dict(bicycle("bicycle_3", 3.4))).parts_fit is None


# --- the anchoring core, frame by frame --------------------------------------------------------

WHOLE = SceneObject("bicycle", "bicycle", (3.0, -5.0, 0.5), size=tuple(BICYCLE))


def run(frames: list[list[SceneObject]]) -> tuple[Anchoring, list]:
    """Frames of percepts (every view said whole: no test saw a part cut), a matcher that compares
    looks (each part of the bicycle has its own), as the learned one does."""
    maker = PerceptMaker(seed=5)
    lifecycle = LifecycleConfig(confirm_after=2, missed_frames_to_missing=1, forget_after=600.0)
    anchoring = Anchoring(AnchoringConfig(lifecycle=lifecycle), matcher=AppearanceRules())
    events, stamp = [], 0.0
    for items in frames:
        percepts = [maker.percept(item, stamp) for item in items]
        events.extend(anchoring.process(percepts, None, stamp, partial=[False] * len(percepts)).events)
        stamp += FRAME
    return anchoring, events


def part(identity: str, y: float, x: float = 3.0) -> SceneObject:
    return SceneObject(identity, "bicycle", (x, y, 0.5), size=tuple(PART))


def test_a_bicycle_moved_and_seen_there_in_parts_ends_as_one_anchor_besides_the_one_it_was():
    frames = [[WHOLE]] * 10 + [[part("front wheel", 3.4)]] * 10 + [[part("middle", 4.0)]] * 10 \
        + [[part("rear wheel", 4.58)]] * 10
    anchoring, events = run(frames)
    anchors = {anchor.symbol: anchor for anchor in anchoring.anchors}
    assert sorted(anchors) == ["bicycle_1", "bicycle_2"]  # where it stood, and where it is
    moved = anchors["bicycle_2"]
    assert moved.state is AnchorState.CONFIRMED and moved.parts_fit is not None
    low, high = moved.position - moved.size / 2, moved.position + moved.size / 2
    assert low[1] == pytest.approx(3.175, abs=0.05) and high[1] == pytest.approx(4.805, abs=0.05)
    joined = [event for event in events
              if event.kind is AnchorEventKind.FORGOTTEN and "parts of one bicycle" in event.details["reason"]]
    assert [event.symbol for event in joined] == ["bicycle_3", "bicycle_4"]


def test_two_bicycles_end_to_end_seen_in_parts_stay_two():
    frames = [[WHOLE]] * 10 + [[part("first", 3.4)]] * 10 + [[part("second", 5.4)]] * 10
    anchoring, _ = run(frames)
    assert sorted(anchor.symbol for anchor in anchoring.anchors) == ["bicycle_1", "bicycle_2", "bicycle_3"]


def test_two_parts_seen_in_one_frame_stay_two_even_after_one_is_out_of_view():
    frames = [[WHOLE]] * 10 + [[part("first", 3.4), part("second", 4.55)]] * 10 + [[part("second", 4.55)]] * 10
    anchoring, _ = run(frames)
    assert sorted(anchor.symbol for anchor in anchoring.anchors) == ["bicycle_1", "bicycle_2", "bicycle_3"]


def test_a_box_joined_from_parts_is_compared_with_a_lost_anchor_without_its_look():
    """Its views are of its parts: a matcher that reads looks must not hold them against the whole
    object's (a search for the bicycle never took the anchor its parts made)."""
    def with_view(anchor: Anchor, seed: int) -> Anchor:
        view = np.abs(np.random.default_rng(seed).normal(size=32)).astype(np.float32)
        anchor.gallery, anchor.gallery_scales = add_view(None, None, view / np.linalg.norm(view), 40.0, 10)
        return anchor

    lost = with_view(bicycle("bicycle_1", 4.0, BICYCLE, first_seen=0.0, state=AnchorState.MISSING,
                             whole_views=20), 1)
    lost.lost_after = 1.0
    candidate = with_view(bicycle("bicycle_2", 4.1, BICYCLE, first_seen=30.0, whole_views=2), 2)
    matcher = AppearanceRules()
    by_look = score_anywhere(matcher, candidate, lost)
    candidate.parts_fit = BICYCLE[[1, 0, 2]] * (1.0 + SLACK)
    without_look = score_anywhere(matcher, candidate, lost)
    assert by_look < 0.5 <= without_look


@pytest.mark.parametrize(("length", "whole_at_last"), [(1.62, True), (1.0, False)],
                         ids=["seen whole from its side", "a larger piece of it"])
def test_a_box_joined_from_parts_seen_whole_at_last_is_compared_by_its_look(length, whole_at_last):
    """The moved bicycle seen in three parts, joined; then seen whole (uncut, 1.62 m of its 1.6):
    from then on it is the anchor of a whole bicycle, whose look a search compares. A larger piece
    (1.0 m) is still a part, and the anchor stays one of parts."""
    seen_whole = SceneObject("bicycle", "bicycle", (3.0, 4.0, 0.5), size=(0.35, length, 1.0))
    frames = [[WHOLE]] * 10 + [[part("front wheel", 3.4)]] * 10 + [[part("middle", 4.0)]] * 10 \
        + [[part("rear wheel", 4.58)]] * 10
    anchoring, _ = run(frames)
    moved = anchoring.get("bicycle_2")
    assert moved.parts_fit is not None
    more, _ = run(frames + [[seen_whole]] * 6)
    moved, before = more.get("bicycle_2"), more.get("bicycle_1")
    assert moved.state is AnchorState.CONFIRMED
    assert (moved.parts_fit is None) is whole_at_last
    assert bool(looks_compared(AppearanceRules(), [moved], before)[0]) is whole_at_last


@pytest.mark.parametrize(("whole", "state", "known", "cleared"), [
    (True, AnchorState.CONFIRMED, BICYCLE[[1, 0, 2]], True),
    (False, AnchorState.CONFIRMED, BICYCLE[[1, 0, 2]], False),  # cut: the camera did not see all of it
    (True, AnchorState.MISSING, BICYCLE[[1, 0, 2]], False),  # a sighting too few to bring it back
    (True, AnchorState.CONFIRMED, None, False),  # no whole one of the class known to span
], ids=["whole", "cut", "still missing", "no extent known"])
def test_only_a_whole_view_spanning_the_known_extent_ends_a_box_of_parts(whole, state, known, cleared):
    joined = bicycle("bicycle_2", 4.0, np.array((0.3, 1.4, 1.0)), state=state, whole_views=2)
    joined.parts_fit = BICYCLE[[1, 0, 2]] * (1.0 + SLACK)
    assert seen_whole_at_last(joined, np.array((0.1, 1.62, 1.0)), whole, known) is cleared
    assert (joined.parts_fit is None) is cleared
