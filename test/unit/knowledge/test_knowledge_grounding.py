"""The grounding relation G, configured as data, applied to anchors."""

from enum import Enum

import numpy as np
import pytest

from merlin2_sailor.errors import ConfigurationError, InvalidInputError
from merlin2_sailor.knowledge import (
    Change,
    Grounding,
    GroundingConfig,
    PddlObject,
    PddlType,
    Predicate,
    Proposition,
    Provenance,
    open_store,
)

CONFIG = {
    "class_types": {"cup": "cup", "Wine Glass": "glass", "person": "person"},
    "fallback_type": "thing",
    "supertypes": {"cup": "container", "glass": "container"},
    "map": {
        "waypoints": [{"name": "kitchen", "x": 0.0, "y": 0.0}, {"name": "sofa", "x": 5.0, "y": 0}],
        "regions": [
            {"name": "living room", "x_min": 3.0, "y_min": -5.0, "x_max": 10.0, "y_max": 5.0},
            {"name": "house", "x_min": -20.0, "y_min": -20.0, "x_max": 20.0, "y_max": 20.0},
        ],
    },
    "max_waypoint_distance": 1.0,
    "size_categories": {"small": 0.3, "large": 100.0},
}


class AnchorState(Enum):
    TENTATIVE = 1
    CONFIRMED = 2
    MISSING = 3


def perceived(predicate, *objects):
    return Proposition(predicate, objects, provenance=Provenance.PERCEIVED)


@pytest.fixture
def grounding():
    return Grounding(GroundingConfig.from_mapping(CONFIG))


def test_an_anchor_becomes_an_object_with_its_facts(grounding, make_anchor):
    result = grounding.ground(
        [make_anchor("cup_1", "cup", 0.5, 0.2, size=np.array([0.1, 0.1, 0.2]))]
    )
    cup = result["cup_1"]
    assert cup.object == PddlObject("cup_1", "cup")
    assert cup.visible
    assert cup.facts == {
        perceived("seen", "cup_1"),
        perceived("visible", "cup_1"),
        perceived("object_at", "cup_1", "kitchen"),
        perceived("small", "cup_1"),
    }


@pytest.mark.parametrize(
    ("x", "y", "location"),
    [
        (0.9, 0.0, "kitchen"),
        (4.2, 0.0, "sofa"),
        (2.0, 0.0, "house"),
        (7.0, 4.0, "living_room"),
        (50.0, 0.0, None),
        (float("nan"), 0.0, None),
    ],
)
def test_location_is_the_nearest_waypoint_else_the_smallest_region(
    grounding, make_anchor, x, y, location
):
    facts = grounding.ground([make_anchor("cup_1", "cup", x, y)])["cup_1"].facts
    places = [fact.objects[1] for fact in facts if fact.predicate == "object_at"]
    assert places == ([location] if location else [])


def test_many_anchors_are_located_in_one_pass(grounding, make_anchor):
    anchors = [make_anchor(f"cup_{i}", "cup", 0.0 if i % 2 else 5.0, 0.1) for i in range(100)]
    result = grounding.ground(anchors)
    assert len(result) == 100
    assert perceived("object_at", "cup_1", "kitchen") in result["cup_1"].facts
    assert perceived("object_at", "cup_2", "sofa") in result["cup_2"].facts


def test_class_names_map_to_types_with_a_fallback(grounding, make_anchor):
    result = grounding.ground(
        [
            make_anchor("wine_glass_1", "wine glass", 0, 0),
            make_anchor("teddy_bear_1", "teddy bear", 0, 0),
            make_anchor("odd_1", "???", 0, 0),
        ]
    )
    assert result["wine_glass_1"].object.type == "glass"
    assert result["teddy_bear_1"].object.type == "thing"
    assert result["odd_1"].object.type == "thing"


def test_an_anchor_out_of_view_is_seen_but_not_visible(grounding, make_anchor):
    result = grounding.ground([make_anchor("cup_1", "cup", 50, 50, visible=False)])
    assert result["cup_1"].facts == {perceived("seen", "cup_1")}
    assert not result["cup_1"].visible


def test_a_missing_anchor_has_no_location_but_a_missing_fact(grounding, make_anchor):
    """The camera saw its place without it: the old location must not reach the planner."""
    result = grounding.ground([make_anchor("cup_1", "cup", 0.1, 0.1, state="missing", visible=False)])
    assert result["cup_1"].facts == {perceived("seen", "cup_1"), perceived("missing", "cup_1")}
    assert result["cup_1"].visible  # fresh evidence: it may overrule what an action expected


def test_waypoints_may_carry_a_heading():
    config = GroundingConfig.from_mapping(
        {"map": {"waypoints": [{"name": "hall", "x": 1, "y": 2, "yaw": 1.5}, {"name": "door", "x": 0, "y": 0}]}}
    )
    assert [(w.name, w.yaw) for w in config.waypoints] == [("hall", 1.5), ("door", None)]
    assert GroundingConfig.from_mapping({"map": {"waypoints": {"hall": [1, 2, -0.5]}}}).waypoints[0].yaw == -0.5


def test_anchors_without_a_symbol_state_are_not_grounded(grounding, make_anchor):
    result = grounding.ground(
        [
            make_anchor("cup_1", "cup", 0, 0, state="tentative"),
            make_anchor("cup_2", "cup", 0, 0, state="FORGOTTEN"),
            make_anchor("cup_3", "cup", 0, 0, state=AnchorState.TENTATIVE),
            make_anchor("cup_4", "cup", 0, 0, state=AnchorState.MISSING),
            make_anchor("cup_5", "cup", 0, 0, state="confirmed"),
        ]
    )
    assert sorted(result) == ["cup_4", "cup_5"]


def test_size_categories_use_the_largest_side(grounding, make_anchor):
    result = grounding.ground(
        [
            make_anchor("cup_1", "cup", 0, 0, size=np.array([0.2, 0.5, 0.1])),
            make_anchor("cup_2", "cup", 0, 0, size=np.array([200.0, 1.0, 1.0])),
            make_anchor("cup_3", "cup", 0, 0),
        ]
    )
    categories = {
        name: {f.predicate for f in grounded.facts} & {"small", "large"}
        for name, grounded in result.items()
    }
    assert categories == {"cup_1": {"large"}, "cup_2": set(), "cup_3": set()}


def test_shared_symbols_are_invalid_input(grounding, make_anchor):
    with pytest.raises(InvalidInputError, match="share the symbol 'cup_1'"):
        grounding.ground([make_anchor("cup_1", "cup", 0, 0), make_anchor("cup_1", "mug", 1, 1)])


def test_declarations_are_accepted_by_a_store_with_the_facts(grounding, make_anchor):
    declarations = grounding.declarations()
    assert PddlType("cup", "container") in declarations
    assert Predicate("object_at", ("object", "wp")) in declarations
    assert PddlObject("living_room", "wp") in declarations
    assert grounding.managed_predicates == {"object_at", "seen", "visible", "missing", "small", "large"}
    grounded = grounding.ground([make_anchor("cup_1", "cup", 7, 0)])["cup_1"]
    with open_store() as store:
        store.apply(
            [Change.save(item) for item in (*declarations, grounded.object, *grounded.facts)]
        )
        assert set(store.propositions_about("cup_1")) == grounded.facts


def test_the_default_configuration_needs_no_map(make_anchor):
    result = Grounding().ground([make_anchor("cup_1", "cup", 0, 0)])
    assert result["cup_1"].object == PddlObject("cup_1", "object")
    assert {f.predicate for f in result["cup_1"].facts} == {"seen", "visible"}


class TestConfiguration:
    def test_waypoints_may_be_a_mapping_and_predicates_renamed(self):
        config = GroundingConfig.from_mapping(
            {"map": {"waypoints": {"Kitchen Table": [1, 2, 0.5]}}, "predicates": {"at": "is at"}}
        )
        assert [(w.name, w.x, w.y) for w in config.waypoints] == [("kitchen_table", 1.0, 2.0)]
        assert config.at_predicate == "is_at"

    def test_from_yaml(self, tmp_path):
        path = tmp_path / "grounding.yaml"
        path.write_text("class_types:\n  cup: mug\nmap:\n  waypoints:\n    wp1: [0, 0]\n")
        config = GroundingConfig.from_yaml(path)
        assert dict(config.class_types) == {"cup": "mug"}

    @pytest.mark.parametrize(
        ("data", "message"),
        [
            ({"class_type": {}}, r"unknown grounding setting\(s\) \['class_type'\]"),
            ({"map": {"waypoints": [{"name": "a", "x": 1}]}}, "malformed"),
            (
                {
                    "map": {
                        "regions": [{"name": "r", "x_min": 1, "y_min": 0, "x_max": 0, "y_max": 1}]
                    }
                },
                "x_min < x_max",
            ),
            ({"max_waypoint_distance": -1}, "positive number"),
            (
                {
                    "map": {
                        "waypoints": {"a": [0, 0]},
                        "regions": [{"name": "A", "x_min": 0, "y_min": 0, "x_max": 1, "y_max": 1}],
                    }
                },
                "distinct names",
            ),
            ({"fallback_type": "!!!"}, "invalid grounding configuration"),
        ],
    )
    def test_mistakes_are_configuration_errors(self, data, message):
        with pytest.raises(ConfigurationError, match=message):
            GroundingConfig.from_mapping(data)

    def test_unreadable_files_are_configuration_errors(self, tmp_path):
        with pytest.raises(ConfigurationError, match="cannot read"):
            GroundingConfig.from_yaml(tmp_path / "missing.yaml")
        (tmp_path / "list.yaml").write_text("- 1\n")
        with pytest.raises(ConfigurationError, match="must hold a mapping"):
            GroundingConfig.from_yaml(tmp_path / "list.yaml")
