"""An anchor pulled off its place by a look-alike goes back when its own object shows up there.

The case comes from the scenario suite (`lookalike_added`, rules, 2 of 3 runs): a blue mug put
0.26 m from a known one while the robot looked away; the first frame back showed only the
newcomer, the known anchor jumped to it, and the known mug, seen on its old spot a frame later,
was anchored anew. Tested below on other offsets, absences and numbers of frames the detector
missed the known mug, then on the rule's limits: an object that really moved, a newcomer of
another colour or class, one that came too late, one that stood there before the jump, a sought
anchor, and the rule turned off.
"""

from __future__ import annotations

import numpy as np
import pytest

from merlin2_sailor.anchoring import AnchorEventKind, Anchoring, AnchoringConfig, Expectation, LifecycleConfig
from merlin2_sailor.anchoring.anchor import Anchor, AnchorState
from merlin2_sailor.anchoring.anchor_index import AnchorIndex
from merlin2_sailor.anchoring.colour_evidence import ColourEvidenceConfig
from merlin2_sailor.anchoring.identity_repair import RepairConfig
from merlin2_sailor.anchoring.place_return import decide_returns, note_jump
from merlin2_sailor.errors import ConfigurationError

from .anchoring_scenes import PerceptMaker, SceneObject, camera_view, mug_colour

FRAME = 1.0 / 15.0
BLUE, RED = 12, 0
MUG = SceneObject("hall_mug", "cup", (2.5, 0.0, 0.8), colour=mug_colour(BLUE))
LIFECYCLE = LifecycleConfig(confirm_after=2, missed_frames_to_missing=1, forget_after=600.0)


def newcomer_at(offset, hue: int = BLUE, class_name: str = "cup") -> SceneObject:
    position = tuple(float(v) for v in np.add(MUG.position, offset))
    return SceneObject("newcomer", class_name, position, looks_like="hall_mug", colour=mug_colour(hue))


def anchoring_of(repair: RepairConfig | None = None) -> Anchoring:
    return Anchoring(AnchoringConfig(lifecycle=LIFECYCLE, repair=repair or RepairConfig()))


def look_away_and_back(
    anchoring: Anchoring, newcomer: SceneObject, away: float = 6.0, mug_missed: int = 1, together: int = 10,
    seed: int = 5,
) -> tuple[tuple[str, str], list]:
    """The mug seen for 10 frames; the camera away for ``away`` s; back, the detector misses the
    mug for ``mug_missed`` frames and sees only the newcomer; then both for ``together`` frames.
    Returns (newcomer's symbol, mug's symbol) in the last frame, and every event."""
    maker, stamp, events = PerceptMaker(seed=seed), 0.0, []
    for _ in range(10):
        events.extend(anchoring.process([maker.percept(MUG, stamp)], camera_view(), stamp).events)
        stamp += FRAME
    stamp += away
    for _ in range(mug_missed):
        events.extend(anchoring.process([maker.percept(newcomer, stamp)], camera_view(), stamp).events)
        stamp += FRAME
    symbols: tuple[str, ...] = ()
    for _ in range(together):
        result = anchoring.process([maker.percept(newcomer, stamp), maker.percept(MUG, stamp)], camera_view(), stamp)
        events.extend(result.events)
        symbols = result.percept_symbols
        stamp += FRAME
    return (symbols[0], symbols[1]), events


@pytest.mark.parametrize("offset", [(0.0, 0.26, 0.0), (0.0, -0.3, 0.0), (0.2, 0.2, 0.0), (-0.35, 0.0, 0.05)])
@pytest.mark.parametrize(("away", "mug_missed"), [(6.0, 1), (3.0, 2), (40.0, 1), (6.0, 4), (1.5, 1)])
def test_a_lookalike_seen_alone_first_does_not_take_the_known_mugs_symbol(offset, away, mug_missed):
    anchoring = anchoring_of()
    (newcomer_symbol, mug_symbol), events = look_away_and_back(anchoring, newcomer_at(offset), away, mug_missed)
    assert mug_symbol == "cup_1"
    assert newcomer_symbol not in ("cup_1", "")
    assert np.linalg.norm(anchoring.get("cup_1").position - MUG.position) < 0.05
    assert np.linalg.norm(anchoring.get(newcomer_symbol).position - newcomer_at(offset).position) < 0.05
    assert [s for s in (a.symbol for a in anchoring.anchors)] == ["cup_1", newcomer_symbol]  # no third anchor


def test_without_the_rule_the_lookalike_takes_the_known_symbol():
    """The same frames with the rule off: the failure the rule exists for."""
    anchoring = anchoring_of(RepairConfig(place_jump=0.0))
    (newcomer_symbol, mug_symbol), _ = look_away_and_back(anchoring, newcomer_at((0.0, 0.26, 0.0)))
    assert newcomer_symbol == "cup_1" and mug_symbol != "cup_1"


def test_the_return_is_said_with_the_other_symbol():
    anchoring = anchoring_of()
    (newcomer_symbol, _), events = look_away_and_back(anchoring, newcomer_at((0.0, 0.26, 0.0)))
    [event] = [e for e in events if "place it had left" in str(e.details.get("reason", ""))]
    assert event.kind is AnchorEventKind.REACQUIRED and event.symbol == "cup_1"
    assert newcomer_symbol in event.details["reason"]


def test_an_object_that_really_moved_keeps_its_symbol():
    """Moved 0.3 m while the camera was away, nothing put in its place: the jump stands."""
    moved = SceneObject("hall_mug", "cup", tuple(np.add(MUG.position, (0.0, 0.3, 0.0))), colour=mug_colour(BLUE))
    anchoring, maker, stamp = anchoring_of(), PerceptMaker(seed=2), 0.0
    for _ in range(10):
        anchoring.process([maker.percept(MUG, stamp)], camera_view(), stamp)
        stamp += FRAME
    stamp += 6.0
    for _ in range(30):
        result = anchoring.process([maker.percept(moved, stamp)], camera_view(), stamp)
        stamp += FRAME
    assert result.percept_symbols == ("cup_1",)
    assert np.linalg.norm(anchoring.get("cup_1").position - moved.position) < 0.05


def test_a_newcomer_of_another_colour_on_the_place_left_is_another_object():
    """The mug moved 0.3 m and a red mug was put where it stood: the red one is not the blue anchor."""
    moved_blue = newcomer_at((0.0, 0.3, 0.0), BLUE)
    red_in_its_place = SceneObject("red_mug", "cup", MUG.position, colour=mug_colour(RED))
    anchoring, maker, stamp = anchoring_of(), PerceptMaker(seed=4), 0.0
    for _ in range(10):
        anchoring.process([maker.percept(MUG, stamp)], camera_view(), stamp)
        stamp += FRAME
    stamp += 6.0
    anchoring.process([maker.percept(moved_blue, stamp)], camera_view(), stamp)
    for _ in range(10):
        stamp += FRAME
        result = anchoring.process([maker.percept(moved_blue, stamp), maker.percept(red_in_its_place, stamp)],
                                   camera_view(), stamp)
    assert result.percept_symbols[0] == "cup_1" and result.percept_symbols[1] != "cup_1"


def test_a_newcomer_of_another_class_changes_nothing():
    anchoring = anchoring_of()
    bowl = SceneObject("bowl", "bowl", MUG.position, colour=mug_colour(BLUE))
    maker, stamp = PerceptMaker(seed=6), 0.0
    for _ in range(10):
        anchoring.process([maker.percept(MUG, stamp)], camera_view(), stamp)
        stamp += FRAME
    stamp += 6.0
    lookalike = newcomer_at((0.0, 0.26, 0.0))
    anchoring.process([maker.percept(lookalike, stamp)], camera_view(), stamp)
    stamp += FRAME
    result = anchoring.process([maker.percept(lookalike, stamp), maker.percept(bowl, stamp)], camera_view(), stamp)
    assert result.percept_symbols == ("cup_1", "bowl_1")


def test_a_newcomer_after_the_review_period_is_not_taken_for_the_anchor():
    """The mug moved; only 3 s later a look-alike appears where it stood (review 2 s)."""
    anchoring = anchoring_of()
    (newcomer_symbol, mug_symbol), _ = look_away_and_back(
        anchoring, newcomer_at((0.0, 0.26, 0.0)), mug_missed=int(3.0 / FRAME))
    assert newcomer_symbol == "cup_1" and mug_symbol != "cup_1"


def jumped_and_newcomer(stamp: float = 10.5, newcomer_first_seen: float = 10.2):
    """A confirmed anchor that jumped 0.26 m at t=10 and a newcomer on the place it left."""
    jumped = Anchor("cup_1", "cup", np.array((2.5, 0.26, 0.8)), np.full(3, 0.1), 0.0, stamp,
                    state=AnchorState.CONFIRMED)
    jumped.left_place, jumped.left_at = np.array(MUG.position), 10.0
    newcomer = Anchor("cup_2", "cup", np.array(MUG.position) + 0.01, np.full(3, 0.1), newcomer_first_seen, stamp)
    index = AnchorIndex()
    index.add(jumped)
    index.add(newcomer)
    return jumped, newcomer, index


def test_decide_returns_pairs_a_jumped_anchor_with_the_newcomer_on_its_place():
    jumped, newcomer, index = jumped_and_newcomer()
    [decision] = decide_returns([newcomer], index, 10.5, 0.15, 2.0, ColourEvidenceConfig())
    assert (decision.anchor, decision.newcomer) == (jumped, newcomer)
    assert decision.jump == pytest.approx(0.26)


@pytest.mark.parametrize(
    ("stamp", "first_seen", "change"),
    [
        (12.5, 12.4, None),  # the review (2 s) is over
        (10.5, 9.0, None),  # the newcomer stood there before the jump: the jump was not away from it
        (10.5, 10.2, "expected"),  # an action expects the anchor somewhere: its expectation settles it
        (10.5, 10.2, "tentative"),  # never confirmed: nothing known to have jumped
    ],
)
def test_decide_returns_leaves_alone(stamp, first_seen, change):
    jumped, newcomer, index = jumped_and_newcomer(stamp, first_seen)
    if change == "expected":
        jumped.expectation = Expectation.at(jumped.position, stamp, source="test")
    if change == "tentative":
        jumped.state = AnchorState.TENTATIVE
    assert decide_returns([newcomer], index, stamp, 0.15, 2.0, ColourEvidenceConfig()) == []


def test_note_jump_records_the_first_place_left_for_the_review_period():
    anchor = Anchor("cup_1", "cup", np.array((1.0, 0.0, 0.8)), np.full(3, 0.1), 0.0, 0.0)
    before = anchor.position.copy()
    anchor.position = before + (0.0, 0.05, 0.0)  # drift: under half a jump
    note_jump(anchor, before, 1.0, 0.15, 2.0)
    assert anchor.left_place is None
    anchor.position = before + (0.0, 0.2, 0.0)
    note_jump(anchor, before + (0.0, 0.05, 0.0), 1.1, 0.15, 2.0)
    assert np.allclose(anchor.left_place, before + (0.0, 0.05, 0.0)) and anchor.left_at == 1.1
    anchor.position = before + (0.0, 0.4, 0.0)
    note_jump(anchor, before + (0.0, 0.2, 0.0), 1.2, 0.15, 2.0)
    assert np.allclose(anchor.left_place, before + (0.0, 0.05, 0.0))  # still pointing home
    note_jump(anchor, anchor.position.copy(), 4.0, 0.15, 2.0)
    assert anchor.left_place is None  # the review is over and it has stood still since


@pytest.mark.parametrize("field", ["place_jump", "place_review"])
@pytest.mark.parametrize("value", [-0.1, float("nan"), float("inf")])
def test_bad_settings_are_refused(field, value):
    with pytest.raises(ConfigurationError, match=field):
        RepairConfig(**{field: value})
