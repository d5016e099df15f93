"""Loading a world file: the shipped house, derived walls, and clear errors for bad files."""

from __future__ import annotations

import copy

import numpy as np
import pytest

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor_demos.world.textures import TextureLibrary
from merlin2_sailor_demos.world.world_file import WorldDescription, load_world

from .worlds import mug, room_mapping


def test_the_house_has_four_rooms_joined_by_doorways_and_a_waypoint_in_each(house_description) -> None:
    house = house_description.house
    assert [room.name for room in house.rooms] == ["kitchen", "living_room", "hall", "bedroom"]
    assert {w.name for w in house.waypoints} == {"kitchen", "living_room", "hall", "bedroom"}
    for waypoint in house.waypoints:
        assert house.room_at(waypoint.pose.x, waypoint.pose.y).name == waypoint.name
    x_min, y_min, x_max, y_max = house.bounds
    assert (x_max - x_min, y_max - y_min) == (10.0, 8.0)
    assert 20 <= len(house_description.objects) <= 50


def test_the_house_has_look_alikes_and_one_red_mug(house_description) -> None:
    textures = {spec.id: spec.texture for spec in house_description.objects}
    rooms = {spec.id: house_description.house.room_at(*spec.xy).name for spec in house_description.objects}
    assert textures["mug_kitchen"] == textures["mug_bedroom"] and rooms["mug_kitchen"] != rooms["mug_bedroom"]
    assert [object_id for object_id, texture in textures.items() if texture == "red_mug"] == ["red_mug"]
    assert house_description.textures["red_mug"].recolor[0] > 150


def test_walls_are_room_edges_merged_and_cut_by_doorways(house_description) -> None:
    house = house_description.house
    # The wall at x = 4.5 is shared by kitchen / living room and the hall: one line, two doorway gaps,
    # split where the kitchen ends so that each piece has one room on each side.
    shared = sorted((wall.start[1], wall.end[1]) for wall in house.walls if wall.start[0] == wall.end[0] == 4.5)
    np.testing.assert_allclose(shared, [(0.0, 1.55), (2.45, 4.0), (4.0, 5.45), (6.35, 8.0)])
    total = sum(wall.length for wall in house.walls)
    outline = 6 + 3 + 4 + 5 + 10 + 8  # the L-shaped house's perimeter
    perimeter_and_inner = outline + 8 + 4.5 + 5  # plus the walls at x = 4.5, y = 4 (kitchen side), x = 6
    assert total == pytest.approx(perimeter_and_inner - sum(door.width for door in house.doorways))


def test_objects_stand_on_the_furniture_under_them(house_description) -> None:
    house = house_description.house
    assert house.support_height(1.9, 2.0) == pytest.approx(0.75)  # the kitchen table
    assert house.support_height(3.0, 3.0) == 0.0


def test_defaults_fill_the_optional_sections() -> None:
    description = WorldDescription.from_mapping(
        {"house": room_mapping()["house"], "textures": {"mug": {"photo": "skimage/coffee"}},
         "objects": [mug("a", 3.0, 2.0)]})
    assert description.robot.start == description.house.waypoints[0].pose
    assert description.camera.width == 640 and description.depth_sensor.maximum_range == 6.0


@pytest.mark.parametrize("change, message", [
    (lambda d: d["house"]["rooms"][0].update(bogus=1), r"unknown field\(s\) \['bogus'\]"),
    (lambda d: d["house"]["rooms"].append({"name": "other", "x_min": 1, "y_min": 1, "x_max": 2, "y_max": 2}),
     "overlap"),
    (lambda d: d["objects"].append(mug("x", 3.0, 2.0) | {"class": "mug"}), "not a COCO class"),
    (lambda d: d["objects"].append(mug("x", 3.0, 2.0) | {"texture": "nope"}), "texture 'nope' is not defined"),
    (lambda d: d["objects"].append(mug("x", 30.0, 2.0)), "in no room"),
    (lambda d: d["objects"].append(mug("x", 3.0, 2.0, size=[0.1, 0.1])), "'size' must be 3 positive numbers"),
    (lambda d: d["objects"].extend([mug("x", 3.0, 2.0), mug("x", 4.0, 2.0)]), "used twice"),
    (lambda d: d["scenario"].append({"when": {"after_seconds": 1}, "move": {"object": "ghost", "to": [1, 1]}}),
     "no object 'ghost'"),
    (lambda d: d["scenario"].append({"when": {"robot_in": "attic"}, "remove": {"object": "a"}}),
     r"unknown room\(s\) \['attic'\]"),
    (lambda d: d["house"]["furniture"].append({"name": "t", "center": [1, 2], "size": [1, 1, 1]}),
     "inside furniture"),
    (lambda d: d["textures"]["mug"].update(photo="flickr/cat"), "skimage/<name>"),
])
def test_mistakes_are_one_clear_error_naming_the_place(change, message) -> None:
    data = copy.deepcopy(room_mapping(objects=[mug("a", 3.0, 2.0)]))
    change(data)
    with pytest.raises(ConfigurationError, match=message):
        description = WorldDescription.from_mapping(data, "test.yaml")
        TextureLibrary(description.textures).get("mug")  # photos are loaded on first use


def test_a_doorway_off_the_shared_wall_is_refused() -> None:
    data = room_mapping()
    data["house"]["rooms"].append({"name": "other", "x_min": 8.0, "y_min": 0.0, "x_max": 10.0, "y_max": 4.0})
    data["house"]["doorways"] = [{"rooms": ["room", "other"], "x": 8.0, "y": 3.8, "width": 0.9}]
    with pytest.raises(ConfigurationError, match="does not fit on the wall shared by 'room' and 'other'"):
        WorldDescription.from_mapping(data)


def test_unreadable_files_say_so(tmp_path) -> None:
    with pytest.raises(ConfigurationError, match="cannot read world file"):
        load_world(tmp_path / "missing.yaml")
    broken = tmp_path / "broken.yaml"
    broken.write_text("house: [unclosed\n")
    with pytest.raises(ConfigurationError, match="broken.yaml is not valid YAML"):
        load_world(broken)
    empty = tmp_path / "empty.yaml"
    empty.write_text("")
    with pytest.raises(ConfigurationError, match="expected a mapping"):
        load_world(empty)
