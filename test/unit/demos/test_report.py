"""The demo's scorecard counts what a user checks by eye on the map, and the map is drawn."""

import cv2
import numpy as np

from merlin2_sailor_demos.report import (
    AnchorRecord,
    IdentityHistory,
    MapLayers,
    TrueObject,
    associate,
    draw_map,
    score,
)

TRUTH = [
    TrueObject("mug_a", "cup", (1.0, 0.0, 0.8)),
    TrueObject("mug_b", "cup", (4.0, 0.0, 0.8)),
    TrueObject("plant", "potted plant", (2.0, 2.0, 0.0)),
    TrueObject("book", "book", (0.0, 3.0, 0.5)),
]


def test_association_is_one_to_one_same_class_and_gated():
    anchors = [
        AnchorRecord("cup_1", "cup", (1.1, 0.0, 0.8)),
        AnchorRecord("cup_2", "cup", (1.2, 0.1, 0.8)),  # a duplicate of mug_a
        AnchorRecord("potted_plant_1", "cup", (2.0, 2.0, 0.0)),  # wrong class: never the plant
        AnchorRecord("book_1", "book", (0.0, 4.0, 0.5)),  # a metre off: beyond the gate
    ]
    assert associate(TRUTH, anchors) == {"mug_a": "cup_1"}


def test_an_anchor_that_sees_its_object_is_preferred_to_a_missing_one_nearer_to_it():
    """A green mug put where the red one stood: the red mug's MISSING anchor is nearer to it than
    the green mug's own anchor, yet says its object is not there; alone, a MISSING anchor still
    anchors the object it stands by (one not seen again yet)."""
    for offset in (0.0, 0.02, 0.2):
        missing = AnchorRecord("cup_1", "cup", (1.0 + offset / 4, 0.0, 0.8), state="missing")
        seeing = AnchorRecord("cup_7", "cup", (1.0 + offset, 0.0, 0.8))
        assert associate(TRUTH, [missing, seeing])["mug_a"] == "cup_7"
        assert associate(TRUTH, [seeing, missing])["mug_a"] == "cup_7"
    assert associate(TRUTH, [AnchorRecord("cup_1", "cup", (1.2, 0.0, 0.8), state="missing")]) == {"mug_a": "cup_1"}
    history = IdentityHistory()
    history.record({"mug_a": "cup_1"})
    replaced = [TrueObject("green_mug", "cup", (1.0, 0.0, 0.8)), *TRUTH[1:]]
    card = score(replaced, [AnchorRecord("cup_1", "cup", (1.0, 0.0, 0.8), state="missing"),
                            AnchorRecord("cup_7", "cup", (1.03, 0.0, 0.8))], history=history)
    assert card.duplicates == () and card.anchored == 1


def test_the_scorecard_counts_misses_duplicates_errors_and_facts():
    anchors = [
        AnchorRecord("cup_1", "cup", (1.1, 0.0, 0.8)),
        AnchorRecord("cup_2", "cup", (1.3, 0.0, 0.8)),
        AnchorRecord("cup_3", "cup", (4.35, 0.0, 0.8)),
        AnchorRecord("potted_plant_1", "potted plant", (2.0, 2.0, 0.0), state="missing"),
        AnchorRecord("book_1", "book", (9.0, 9.0, 0.5)),
        AnchorRecord("book_2", "book", (0.0, 3.0, 0.5), state="tentative"),  # no claim yet
    ]
    places = {"mug_a": "kitchen", "mug_b": "hall", "plant": "kitchen"}
    card = score(
        TRUTH,
        anchors,
        facts=[("cup_1", "kitchen"), ("cup_3", "kitchen"), ("book_1", "bedroom")],
        place_of=lambda obj: places.get(obj.id),
    )
    assert card.anchored == 3 and card.not_anchored == ("book",)
    assert card.duplicates == ("cup_2",) and card.spurious == ("book_1",)
    assert card.wrong_positions == ("mug_b",)
    assert abs(card.position_errors["mug_b"] - 0.35) < 1e-9
    assert card.facts_right == 1
    assert card.facts_wrong == ("object_at(cup_3, kitchen)", "object_at(book_1, bedroom)")
    table = card.to_markdown()
    assert "| anchored (exactly one anchor each) | 3 / 4 |" in table and "book_1" in table


def test_the_missing_anchor_of_a_removed_object_is_no_duplicate():
    """The red mug was taken out of the house: its anchor, MISSING where it stood beside another
    mug, is what should remain; confirmed there it would still claim a mug that is gone."""
    history = IdentityHistory()
    history.record({"mug_a": "cup_1", "mug_b": "cup_2"})
    without_mug_a = TRUTH[1:]
    near_mug_b = (4.3, 0.0, 0.8)
    missing = score(without_mug_a, [AnchorRecord("cup_2", "cup", (4.0, 0.0, 0.8)),
                                    AnchorRecord("cup_1", "cup", near_mug_b, state="missing")], history=history)
    assert missing.duplicates == () and missing.spurious == ()
    confirmed = score(without_mug_a, [AnchorRecord("cup_2", "cup", (4.0, 0.0, 0.8)),
                                      AnchorRecord("cup_1", "cup", near_mug_b)], history=history)
    assert confirmed.duplicates == ("cup_1",)
    never_an_object = score(TRUTH, [AnchorRecord("cup_1", "cup", (1.0, 0.0, 0.8)),
                                    AnchorRecord("cup_9", "cup", (1.3, 0.0, 0.8), state="missing")])
    assert never_an_object.duplicates == ("cup_9",)


def test_a_missing_anchor_said_indistinguishable_from_an_anchored_object_is_undecided_not_a_duplicate():
    """A twin found where the camera never looked: the sought anchor stays missing beside its
    candidate's, the anchoring layer naming the candidate. A doubt it states is not a duplicate it
    does not know of; a named partner that anchors nothing, or of another class, excuses nothing."""
    mug_a_moved = (1.4, 0.0, 0.8)
    twin_left = AnchorRecord("cup_1", "cup", (1.0, 0.0, 0.8), "missing", ("cup_7",))
    found = AnchorRecord("cup_7", "cup", mug_a_moved)
    card = score([TrueObject("mug_a", "cup", mug_a_moved), *TRUTH[1:]],
                 [twin_left, found, AnchorRecord("cup_2", "cup", (4.0, 0.0, 0.8))])
    assert card.undecided == ("cup_1",) and card.duplicates == ()
    assert card.to_dict()["undecided"] == ["cup_1"]
    assert "| missing, said to be indistinguishable from another | cup_1 |" in card.to_markdown()
    beside_mug_a, on_mug_a = (1.3, 0.0, 0.8), (1.0, 0.0, 0.8)
    named_nothing = AnchorRecord("cup_1", "cup", beside_mug_a, "missing", ("cup_99",))
    assert score(TRUTH, [named_nothing, AnchorRecord("cup_7", "cup", on_mug_a)]).duplicates == ("cup_1",)
    confirmed = AnchorRecord("cup_1", "cup", beside_mug_a, "confirmed", ("cup_7",))
    card = score(TRUTH, [confirmed, AnchorRecord("cup_7", "cup", on_mug_a)])
    assert card.duplicates == ("cup_1",) and card.undecided == ()
    other_class = AnchorRecord("cup_1", "cup", beside_mug_a, "missing", ("book_1",))
    card = score(TRUTH, [other_class, AnchorRecord("cup_7", "cup", on_mug_a),
                         AnchorRecord("book_1", "book", (0.0, 3.0, 0.5))])
    assert card.duplicates == ("cup_1",)


def test_identity_switches_are_symbol_changes_of_one_object():
    history = IdentityHistory()
    history.record({"mug_a": "cup_1", "mug_b": "cup_2"})
    history.record({"mug_a": "cup_1"})  # mug_b out of view: no switch
    history.record({"mug_a": "cup_2", "mug_b": "cup_1"})  # the look-alikes swapped symbols
    history.record({"mug_a": "cup_2", "mug_b": "cup_1"})
    assert history.switches == {"mug_a": 1, "mug_b": 1}
    assert history.symbols["mug_a"] == ["cup_1", "cup_2"]
    card = score(TRUTH[:2], [AnchorRecord("cup_2", "cup", (1, 0, 0.8)), AnchorRecord("cup_1", "cup", (4, 0, 0.8))],
                 history=history)
    assert card.total_switches == 2


def test_the_map_is_a_png_with_everything_drawn(tmp_path):
    layers = MapLayers(
        rooms=[("kitchen", (0.0, -1.0, 3.0, 2.0)), ("hall", (3.0, -1.0, 6.0, 4.0))],
        furniture=[(0.5, -0.5, 1.5, 0.5)],
        waypoints=[("kitchen", 1.5, 1.0), ("hall", 4.5, 1.0)],
        robot_path=[(1.5, 1.0), (3.0, 1.0), (4.5, 1.0)],
    )
    anchors = [AnchorRecord("cup_1", "cup", (1.1, 0.0, 0.8)), AnchorRecord("cup_2", "cup", (4.0, 0.2, 0.8), "missing")]
    path = draw_map(tmp_path / "map.png", layers, TRUTH, anchors, associate(TRUTH, anchors), title="run")
    image = cv2.imread(str(path))
    assert image is not None and image.shape[0] > 200 and image.shape[1] > 300
    colours = {tuple(c) for c in image.reshape(-1, 3)[:: 7].tolist()}
    assert (60, 160, 60) in colours  # true objects
    assert (40, 40, 220) in colours  # the missing anchor
    assert np.count_nonzero(np.all(image == (200, 90, 30), axis=2)) > 10  # the confirmed anchor


def test_anchors_are_projected_into_the_frame_where_they_are():
    from merlin2_sailor.contract.camera import CameraIntrinsics
    from merlin2_sailor.contract.pose import Pose
    from merlin2_sailor_demos.report.annotated_frame import AnchorInView, anchor_box, annotate_frame

    intrinsics = CameraIntrinsics(fx=500.0, fy=500.0, cx=320.0, cy=240.0, width=640, height=480)
    # Optical frame (z forward, x right, y down) looking along world +x from (0, 0, 1).
    camera = Pose(np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]]), np.array([0.0, 0.0, 1.0]))
    ahead = AnchorInView("cup_1", "confirmed", (2.0, 0.0, 1.0), (0.2, 0.2, 0.2), seen_now=True)
    x0, y0, x1, y1 = anchor_box(ahead, intrinsics, camera)
    assert abs((x0 + x1) / 2 - 320) <= 1 and abs((y0 + y1) / 2 - 240) <= 1
    assert 50 <= x1 - x0 <= 60  # 0.2 m at 1.9-2.1 m with f = 500 px
    behind = AnchorInView("cup_2", "missing", (-2.0, 0.0, 1.0), (0.2, 0.2, 0.2), seen_now=False)
    assert anchor_box(behind, intrinsics, camera) is None
    frame = np.zeros((480, 640, 3), dtype=np.uint8)
    drawn = annotate_frame(frame, intrinsics, camera, [ahead, behind], [(300, 220, 340, 260)], caption="t=1.0 s")
    assert frame.max() == 0  # the input is left alone
    assert np.all(drawn[y0, x0 + 5 : x1 - 5] == (30, 90, 200))  # the anchor's box edge, confirmed colour
    assert drawn[460:478, 0:80].max() == 255  # the caption


def test_an_anchor_behind_a_wall_is_not_drawn_and_one_in_view_is():
    from merlin2_sailor.contract.camera import CameraIntrinsics
    from merlin2_sailor.contract.pose import Pose
    from merlin2_sailor_demos.report.annotated_frame import AnchorInView, anchor_box, annotate_frame

    intrinsics = CameraIntrinsics(fx=500.0, fy=500.0, cx=320.0, cy=240.0, width=640, height=480)
    camera = Pose(np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]]), np.array([0.0, 0.0, 1.0]))
    cup = AnchorInView("cup_1", "confirmed", (2.0, 0.0, 1.0), (0.2, 0.2, 0.2), seen_now=False)
    x0, y0, x1, y1 = anchor_box(cup, intrinsics, camera)
    frame = np.zeros((480, 640, 3), dtype=np.uint8)

    def drawn_with(depth: np.ndarray) -> bool:
        image = annotate_frame(frame, intrinsics, camera, [cup], depth=depth)
        return bool(np.all(image[y0, x0 + 5 : x1 - 5] == (30, 90, 200)))

    wall = np.full((480, 640), 1.0, dtype=np.float32)  # a wall 1 m ahead, the cup 2 m ahead
    assert not drawn_with(wall)
    cup_surface = np.full((480, 640), 1.9, dtype=np.float32)  # the camera sees the cup itself
    assert drawn_with(cup_surface)
    assert drawn_with(np.full((480, 640), np.nan, dtype=np.float32))  # no depth proves nothing
    door_frame = cup_surface.copy()
    door_frame[:, : (x0 + x1) // 2] = 1.0  # half the cup behind a door frame: still in view
    assert drawn_with(door_frame)
    without_depth = annotate_frame(frame, intrinsics, camera, [cup])
    assert np.all(without_depth[y0, x0 + 5 : x1 - 5] == (30, 90, 200))  # no depth given: drawn as before


def test_each_duplicate_is_explained_by_why_it_and_its_neighbour_were_anchored_anew():
    from merlin2_sailor_demos.report.writer import explain_duplicates

    anchors = [
        AnchorRecord("cup_1", "cup", (1.1, 0.0, 0.8), state="missing"),
        AnchorRecord("cup_2", "cup", (1.0, 0.05, 0.8)),  # the nearer to mug_a: it anchors it
        AnchorRecord("cup_3", "cup", (4.0, 0.0, 0.8)),
        AnchorRecord("book_1", "book", (1.1, 0.0, 0.8)),  # nearest, but of another class
    ]
    card = score(TRUTH, anchors)
    associated = set(associate(TRUTH, [a for a in anchors if a.state in ("confirmed", "missing")]).values())
    assert card.duplicates == ("cup_1",) and "cup_2" in associated
    origins = explain_duplicates(card.duplicates, anchors, associated, {"cup_2": "cup_1 ruled out by colour"})
    assert origins == {"cup_1": "cup_1 (missing), anchored anew: no anchor of its class within the matching gate; "
                                "beside cup_2 (confirmed, 0.11 m), anchored anew: cup_1 ruled out by colour"}
    assert explain_duplicates((), anchors, associated, {}) == {}
