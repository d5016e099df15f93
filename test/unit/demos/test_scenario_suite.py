"""The scenario suite's world files: each loads, names what exists, and has a well-formed right outcome."""

from __future__ import annotations

import pytest

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor.knowledge.grounding import GroundingConfig
from merlin2_sailor_demos.scenarios import DEFAULT_SCENARIO, all_scenarios, find_scenario, scenario_names
from merlin2_sailor_demos.world.mission import ExpectedOutcome, MissionSpec, RouteStop
from merlin2_sailor_demos.world.world_file import WorldDescription, load_world

from .world.worlds import HOUSE_FILE, HOUSE_GROUNDING_FILE, mug, room_mapping

#: The issue's eight situations, each a scenario of its own.
REQUIRED = ("twin_moved", "moved_beside_other_colour", "removed", "swapped", "lookalike_added",
            "moved_while_watched", "moved_and_moved_back", "crowded_shelf")


def test_the_suite_has_the_default_and_every_required_situation() -> None:
    names = scenario_names()
    assert names[0] == DEFAULT_SCENARIO and set(REQUIRED) <= set(names) and len(names) >= 9


@pytest.fixture(scope="module")
def scenarios():
    return all_scenarios()


def test_every_scenario_loads_with_a_description_and_names_only_what_exists(scenarios) -> None:
    house = load_world(HOUSE_FILE)
    for entry in scenarios:
        world = load_world(entry.path)  # checked on loading: target, waypoints, awaited events
        assert entry.description and "\n" not in entry.description, entry.name
        initial = {spec.id for spec in world.objects}
        added = {event.object_id for event in world.scenario if event.action == "add"}
        assert entry.mission.target in initial, entry.name
        assert set(entry.mission.expect.object_ids) <= initial | added, entry.name
        # Every scenario keeps the house's rooms and waypoints: they share its grounding.
        assert world.house.rooms == house.house.rooms and world.house.waypoints == house.house.waypoints, entry.name


def test_every_scenario_shares_the_house_grounding(scenarios) -> None:
    grounding = {(w.name, w.x, w.y) for w in GroundingConfig.from_yaml(HOUSE_GROUNDING_FILE).waypoints}
    for entry in scenarios:
        world = load_world(entry.path)
        assert {(w.name, w.pose.x, w.pose.y) for w in world.house.waypoints} == grounding, entry.name


def test_every_scenario_changes_what_its_mission_is_about(scenarios) -> None:
    by_name = {entry.name: entry for entry in scenarios}
    for name in REQUIRED:
        entry = by_name[name]
        world = load_world(entry.path)
        awaited = {event for stop in entry.mission.route for event in stop.wait_for or ()}
        assert awaited == {event.name for event in world.scenario}, name  # the mission waits for every change
    removed = load_world(by_name["removed"].path)
    assert by_name["removed"].mission.expect.outcome is ExpectedOutcome.NOT_FOUND
    assert [(event.action, event.object_id) for event in removed.scenario] == [("remove", "red_mug")]
    assert by_name["twin_moved"].mission.expect.unknown_allowed  # true twins: "cannot tell apart" is honest
    assert all(not by_name[name].mission.expect.unknown_allowed for name in REQUIRED if name != "twin_moved")


def test_the_look_alikes_the_scenarios_rely_on_are_real() -> None:
    twin = load_world(find_scenario("twin_moved").path)
    textures = {spec.id: spec.texture for spec in twin.objects}
    assert textures["blue_mug_kitchen"] == textures["blue_mug_hall"]
    added = load_world(find_scenario("lookalike_added").path)
    (event,) = added.scenario
    assert event.action == "add" and event.spec.texture == textures["blue_mug_hall"]
    shelf = load_world(find_scenario("crowded_shelf").path)
    books = [spec for spec in shelf.objects if spec.id.startswith("shelf_book")]
    assert len(books) == 7 and len({spec.texture for spec in books}) < len(books)
    gaps = [b.xy[0] - a.xy[0] - a.size[0] for a, b in zip(books, books[1:], strict=False)]
    assert max(gaps) <= 0.05  # crowded: a few centimetres between books
    watched = load_world(find_scenario("moved_while_watched").path)
    assert watched.scenario[0].watched and watched.scenario[0].speed


def test_the_default_is_the_house_with_the_default_story() -> None:
    entry = find_scenario(DEFAULT_SCENARIO)
    assert entry.path == HOUSE_FILE.resolve() or entry.path.samefile(HOUSE_FILE)
    assert entry.mission == MissionSpec()
    assert entry.mission.target == "red_mug" and entry.mission.route == (RouteStop("hall"),)
    assert entry.mission.explore is None and entry.mission.expect.outcome is ExpectedOutcome.FOUND


def test_an_unknown_scenario_lists_the_others() -> None:
    with pytest.raises(ConfigurationError, match="no scenario 'nope'; scenarios: default, "):
        find_scenario("nope")


@pytest.mark.parametrize("mission, message", [
    ({"target": "ghost"}, "the target 'ghost' is not an object at the start"),
    ({"explore": ["attic"]}, r"unknown waypoint\(s\) \['attic'\]"),
    ({"route": [{"go_to": "attic"}]}, r"unknown waypoint\(s\) \['attic'\]"),
    ({"route": [{"wait_for": ["never"]}]}, r"waits for unknown event\(s\) \['never'\]"),
    ({"expect": {"outcome": "maybe"}}, "'outcome' must be one of found, not_found"),
    ({"expect": {"keep_symbols": ["ghost"]}}, r"no object\(s\) \['ghost'\]"),
    ({"expect": {"surely": True}}, "unknown field"),
])
def test_a_wrong_mission_says_what_is_wrong(mission, message) -> None:
    mapping = room_mapping(objects=[mug("a", 3.0, 2.0)])
    mapping["mission"] = {"target": "a", "route": [], **mission}
    with pytest.raises(ConfigurationError, match=message):
        WorldDescription.from_mapping(mapping, "room")


def test_a_mission_may_expect_an_object_an_event_adds() -> None:
    mapping = room_mapping(objects=[mug("a", 3.0, 2.0)], scenario=[{"name": "b_arrives", "add": mug("b", 5.0, 2.0)}])
    mapping["mission"] = {"target": "a", "route": [{"wait_for": ["b_arrives"]}], "expect": {"new_symbols": ["b"]}}
    mission = WorldDescription.from_mapping(mapping, "room").mission
    assert mission.route == (RouteStop(None, ("b_arrives",)),) and mission.expect.new_symbols == ("b",)
    assert MissionSpec.from_mapping(mission.as_dict(), "again") == mission  # as_dict is what scorecards keep
