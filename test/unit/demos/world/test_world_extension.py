"""A world file that extends another lists only its differences; the result is checked as a whole."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from merlin2_sailor.errors import ConfigurationError
from merlin2_sailor_demos.world.world_file import WorldDescription, load_world

from .worlds import mug, room_mapping


def _write(path: Path, data: dict) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.fixture
def base(tmp_path) -> Path:
    mapping = room_mapping(objects=[mug("a", 3.0, 2.0), mug("b", 5.0, 2.0), mug("c", 6.0, 1.0)],
                           scenario=[{"name": "a_leaves", "when": {"after_seconds": 1.0},
                                      "move": {"object": "a", "to": [1.0, 1.0]}}])
    mapping["robot"]["radius"] = 0.3
    mapping["description"] = "the base room"
    mapping["mission"] = {"target": "a", "route": []}
    return _write(tmp_path / "base.yaml", mapping)


def test_objects_merge_by_id_and_removals_leave_them_out(base) -> None:
    derived = _write(base.parent / "scenarios" / "derived.yaml", {
        "extends": "../base.yaml",
        "remove_objects": ["c"],
        "objects": [{"id": "a", "position": [4.0, 3.0]}, mug("d", 7.0, 3.0)],
    })
    world = load_world(derived)
    by_id = {spec.id: spec for spec in world.objects}
    assert list(by_id) == ["a", "b", "d"]  # the base's order, additions last
    assert by_id["a"].xy == (4.0, 3.0) and by_id["a"].size == (0.3, 0.3, 0.3) and by_id["a"].texture == "mug"
    assert by_id["d"].xy == (7.0, 3.0)


def test_mapping_sections_merge_key_by_key_and_the_scenario_is_inherited_unless_given(base) -> None:
    inherits = load_world(_write(base.parent / "inherits.yaml", {"extends": "base.yaml",
                                                                  "robot": {"start": [2.0, 1.0, 0.5]}}))
    assert (inherits.robot.start.x, inherits.robot.start.y) == (2.0, 1.0) and inherits.robot.radius == 0.3
    assert [event.name for event in inherits.scenario] == ["a_leaves"]
    replaces = load_world(_write(base.parent / "replaces.yaml", {"extends": "base.yaml", "scenario": []}))
    assert replaces.scenario == ()


def test_description_and_mission_describe_their_own_file_only(base) -> None:
    assert load_world(base).mission.target == "a"
    derived = load_world(_write(base.parent / "plain.yaml", {"extends": "base.yaml"}))
    assert derived.description == "" and derived.mission is None
    own = load_world(_write(base.parent / "own.yaml", {"extends": "base.yaml", "description": "mine",
                                                       "mission": {"target": "b", "route": []}}))
    assert own.description == "mine" and own.mission.target == "b"


def test_a_base_may_extend_another(base) -> None:
    middle = _write(base.parent / "middle.yaml", {"extends": "base.yaml", "remove_objects": ["b"]})
    top = load_world(_write(base.parent / "top.yaml", {"extends": middle.name, "objects": [{"id": "c",
                                                                                             "position": [1.0, 3.0]}]}))
    assert {spec.id: spec.xy for spec in top.objects} == {"a": (3.0, 2.0), "c": (1.0, 3.0)}


@pytest.mark.parametrize("changes, message", [
    ({"remove_objects": ["nothing"]}, "remove_objects names 'nothing', which the base does not have"),
    ({"remove_objects": ["a"], "objects": [{"id": "a", "position": [1.0, 1.0]}]}, "which remove_objects removes"),
    ({"objects": [{"position": [1.0, 1.0]}]}, r"objects\[0\] must be a mapping with an 'id'"),
    ({"objects": [{"id": "new", "position": [1.0, 1.0]}]}, "'class' is required"),
    ({"remove_objects": "a"}, "must be a list of object ids"),
    # The merged world is checked as any world: removing the object an event moves is caught.
    ({"remove_objects": ["a"]}, "no object 'a'"),
])
def test_a_wrong_extension_says_what_is_wrong(base, changes, message) -> None:
    derived = _write(base.parent / "wrong.yaml", {"extends": "base.yaml", **changes})
    with pytest.raises(ConfigurationError, match=message):
        load_world(derived)


def test_missing_bases_cycles_and_mappings_are_refused(tmp_path, base) -> None:
    with pytest.raises(ConfigurationError, match="extends nowhere.yaml, which does not exist"):
        load_world(_write(tmp_path / "lost.yaml", {"extends": "nowhere.yaml"}))
    _write(tmp_path / "one.yaml", {"extends": "two.yaml"})
    with pytest.raises(ConfigurationError, match="cycle: two.yaml -> one.yaml -> two.yaml"):
        load_world(_write(tmp_path / "two.yaml", {"extends": "one.yaml"}))
    with pytest.raises(ConfigurationError, match="remove_objects' needs 'extends'"):
        load_world(_write(tmp_path / "alone.yaml", {**room_mapping(), "remove_objects": ["a"]}))
    with pytest.raises(ConfigurationError, match="work in a world file"):
        WorldDescription.from_mapping({"extends": "base.yaml"}, "inline")


def test_the_house_itself_loads_unchanged_through_the_same_reader(house_description) -> None:
    assert house_description.mission is None and house_description.description
    assert [event.name for event in house_description.scenario] == ["red_mug_moves_to_the_living_room"]
