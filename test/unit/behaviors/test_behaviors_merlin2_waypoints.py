"""SAILOR's map as MERLIN2's waypoint_navigation node reads its waypoints."""

from __future__ import annotations

import math

import yaml

from merlin2_sailor_behaviors.actions.places import Place, Places
from merlin2_sailor_behaviors.merlin2.waypoints import main, parameter_file, waypoint_navigation_parameters


def test_each_waypoint_is_five_strings_name_x_y_and_the_heading_as_quaternion_z_w() -> None:
    places = Places([Place("kitchen", 2.5, 2.0, math.pi / 2), Place("hall", -1.0, 0.25),
                     Place("table_area", 1.0, 1.0, is_waypoint=False)])
    values = waypoint_navigation_parameters(places)
    assert all(isinstance(value, str) for value in values)
    assert len(values) == 10  # regions are no waypoints
    name, x, y, z, w = values[:5]
    assert (name, float(x), float(y)) == ("kitchen", 2.5, 2.0)
    assert math.isclose(2 * math.atan2(float(z), float(w)), math.pi / 2)
    assert values[5:] == ["hall", "-1.0", "0.25", "0.0", "1.0"]  # no heading: 0


def test_the_parameter_file_is_for_the_node_in_its_launch_namespace() -> None:
    places = Places([Place("kitchen", 2.5, 2.0, 0.0)])
    document = yaml.safe_load(parameter_file(places))
    assert document == {"waypoint_navigation": {"waypoint_navigation_node": {
        "ros__parameters": {"wps": ["kitchen", "2.5", "2.0", "0.0", "1.0"]}}}}


def test_a_missing_map_is_one_line_and_status_2(tmp_path, capsys) -> None:
    assert main([str(tmp_path / "nowhere.yaml")]) == 2
    assert capsys.readouterr().err.startswith("cannot read the map:")
