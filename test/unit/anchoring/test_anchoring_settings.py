"""The anchoring settings: one table, defaults read from the dataclasses, parameter files read as rcl does.

The table must cover every field of the config tree (a new field without a row fails here), and
config/anchoring.yaml must document every row with the dataclass default as its value.
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import pytest
import yaml

from merlin2_sailor.anchoring.lifecycle import LifecycleConfig
from merlin2_sailor.anchoring.settings import (
    SETTINGS,
    SETTINGS_BY_NAME,
    AnchoringSettings,
    default_settings,
    load_anchoring_settings,
    parameter_values,
    read_parameter_file,
    render_parameter_file,
    settings_from_parameters,
    value_at,
)
from merlin2_sailor.anchoring.visibility import VisibilityConfig
from merlin2_sailor.errors import ConfigurationError

CONFIG = Path(__file__).resolve().parents[3] / "config" / "anchoring.yaml"


def leaf_paths(instance: object, prefix: tuple[str, ...] = ()) -> list[tuple[str, ...]]:
    """Every non-dataclass field under ``instance``, as attribute paths."""
    paths = []
    for field in dataclasses.fields(instance):  # type: ignore[arg-type]
        value = getattr(instance, field.name)
        if dataclasses.is_dataclass(value):
            paths += leaf_paths(value, (*prefix, field.name))
        else:
            paths.append((*prefix, field.name))
    return paths


def write(path: Path, document: object) -> Path:
    path.write_text(yaml.safe_dump(document, sort_keys=False))
    return path


def test_every_field_of_the_config_tree_has_exactly_one_row_and_every_row_a_field() -> None:
    rows = [row.path for row in SETTINGS]
    assert len(rows) == len(set(rows)), "two rows set the same field"
    assert len(SETTINGS_BY_NAME) == len(SETTINGS), "two rows share a name"
    missing = set(leaf_paths(AnchoringSettings())) - set(rows)
    assert not missing, f"fields without a row in merlin2_sailor/anchoring/settings.py: {sorted(missing)}"
    for row in SETTINGS:
        assert not dataclasses.is_dataclass(row.default), f"{row.name} points at a whole dataclass"
        assert row.description.endswith("."), row.name


def test_the_defaults_are_the_deployed_ones_and_come_from_the_dataclasses() -> None:
    # One set of defaults: what the robot ran (600 s, 6 m) is what the core's dataclasses say.
    assert SETTINGS_BY_NAME["forget_after"].default == LifecycleConfig().forget_after == 600.0
    assert SETTINGS_BY_NAME["visible_range"].default == VisibilityConfig().frustum.far == 6.0
    assert parameter_values(default_settings()) == {row.name: row.default for row in SETTINGS}


def test_config_anchoring_yaml_holds_every_default_and_documents_every_row() -> None:
    document = yaml.safe_load(CONFIG.read_text())
    values = document["/**/anchoring"]["ros__parameters"]
    assert set(values) == set(SETTINGS_BY_NAME)
    for name, value in values.items():
        row = SETTINGS_BY_NAME[name]
        if not row.deployment:
            assert value == row.default and type(value) is type(row.default), (name, value, row.default)
    # Each key's comment block says what its row says.
    comments: list[str] = []
    for line in CONFIG.read_text().splitlines():
        stripped = line.strip()
        if stripped.startswith("#"):
            comments.append(stripped.lstrip("# "))
            continue
        key = re.match(r"(\w+):", stripped)
        if key and key.group(1) in SETTINGS_BY_NAME:
            said = " ".join(comments)
            assert " ".join(SETTINGS_BY_NAME[key.group(1)].description.split()) in said, key.group(1)
        comments = []
    # Regenerating the file from the table changes nothing but what deployments chose.
    assert yaml.safe_load(render_parameter_file()) == {
        "/**/anchoring": {"ros__parameters": {row.name: row.default for row in SETTINGS}}}


def test_values_are_applied_generically_and_fields_checked_together_are_set_together() -> None:
    # Set one at a time, the sigmas would fail (position 1.5 above the default cap of 1.0).
    settings = settings_from_parameters({
        "rules_position_sigma": 1.5, "rules_maximum_sigma": 2.0, "forget_after": 42.0, "visible_near": 0.5,
        "confirm_after": 5, "gate_class_mismatch": False, "matcher": "rules", "world_frame": "odom",
        "reappearance_distance": 0.1, "sync_period": 1.5,
    })
    assert (settings.matcher.rules.position_sigma, settings.matcher.rules.maximum_sigma) == (1.5, 2.0)
    assert settings.core.lifecycle == dataclasses.replace(LifecycleConfig(), forget_after=42.0, confirm_after=5)
    assert settings.core.visibility.frustum.near == 0.5 and settings.core.visibility.frustum.far == 6.0
    assert settings.core.table.gate_class_mismatch is False and settings.core.world_frame == "odom"
    assert settings.matcher.name == "rules" and settings.persistence.sync_period == 1.5
    # Every other value is the default, and reading the values back gives what was set.
    values = parameter_values(settings)
    changed = {name for name, value in values.items() if value != SETTINGS_BY_NAME[name].default}
    assert changed == {"rules_position_sigma", "rules_maximum_sigma", "forget_after", "visible_near",
                       "confirm_after", "gate_class_mismatch", "matcher", "world_frame", "reappearance_distance",
                       "sync_period"}
    assert settings_from_parameters(values) == settings


@pytest.mark.parametrize(("values", "message"), [
    ({"forget_after": 600}, "must be a float, got 600 (write 600.0)"),
    ({"confirm_after": 2.0}, "must be an integer, got 2.0"),
    ({"gate_class_mismatch": "no"}, "must be true or false"),
    ({"visible_range": 0.1}, "must be 0.3 to 1000, got 0.1"),
    ({"match_threshold": float("nan")}, "must be 0.01 to 1"),
    ({"matcher": "neural"}, "must be one of network, rules"),
    ({"forget_afterr": 5.0}, "did you mean 'forget_after'"),
    ({"visible_near": 7.0}, "near < far"),  # in range, refused by the dataclass's own check
])
def test_bad_values_are_refused_saying_which_parameter_and_where(values, message) -> None:
    with pytest.raises(ConfigurationError, match=re.escape(message)) as caught:
        settings_from_parameters(values, dict.fromkeys(values, "my.yaml"))
    assert "my.yaml" in str(caught.value)


def test_parameter_files_are_read_as_rcl_matches_node_names(tmp_path) -> None:
    file = write(tmp_path / "params.yaml", {
        "/**": {"ros__parameters": {"use_sim_time": True, "forget_after": 1.0, "confirm_after": 2}},
        "/**/anchoring": {"ros__parameters": {"forget_after": 2.0}},  # later: wins over /**
        "/*/anchoring": {"ros__parameters": {"visible_range": 3.0}},  # one namespace: not the root node
        "/robot/anchoring": {"ros__parameters": {"gate_base": 2.5}},
        "percept_generator": {"ros__parameters": {"maximum_depth": 4.5}},  # another node
        "robot": {"anchoring": {"ros__parameters": {"confirm_after": 7}}},  # nested namespace
    })
    assert read_parameter_file(file, "/anchoring") == {"forget_after": 2.0, "confirm_after": 2}
    assert read_parameter_file(file, "/robot/anchoring") == {
        "forget_after": 2.0, "confirm_after": 7, "visible_range": 3.0, "gate_base": 2.5}
    assert read_parameter_file(file, "/a/b/anchoring") == {"forget_after": 2.0, "confirm_after": 2}
    settings = load_anchoring_settings(file, {"confirm_after": 4}, overrides={"forget_after": 9.0})
    assert (settings.core.lifecycle.confirm_after, settings.core.lifecycle.forget_after) == (4, 9.0)


def test_a_section_for_this_node_must_name_known_parameters_but_one_for_every_node_need_not(tmp_path) -> None:
    shared = write(tmp_path / "shared.yaml", {"/**": {"ros__parameters": {"report_period": 5.0}}})
    assert load_anchoring_settings(shared) == default_settings()
    own = write(tmp_path / "own.yaml", {"anchoring": {"ros__parameters": {"visible_rnage": 5.0}}})
    with pytest.raises(ConfigurationError, match=r"unknown anchoring parameter 'visible_rnage' in .*own.yaml; "
                                                 r"did you mean 'visible_range'"):
        load_anchoring_settings(own)
    nested = write(tmp_path / "nested.yaml", {"anchoring": {"ros__parameters": {"rules": {"sigma": 1.0}}}})
    with pytest.raises(ConfigurationError, match="'rules.sigma'"):
        load_anchoring_settings(nested)


def test_unreadable_parameter_files_are_one_clear_error(tmp_path) -> None:
    with pytest.raises(ConfigurationError, match="cannot read the parameter file"):
        load_anchoring_settings(tmp_path / "absent.yaml")
    (tmp_path / "bad.yaml").write_text("anchoring: [1, 2\n")
    with pytest.raises(ConfigurationError, match="is not valid YAML"):
        load_anchoring_settings(tmp_path / "bad.yaml")
    write(tmp_path / "flat.yaml", {"anchoring": 3})
    with pytest.raises(ConfigurationError, match="must hold a ros__parameters mapping"):
        load_anchoring_settings(tmp_path / "flat.yaml")


def test_the_shipped_launch_files_give_the_anchoring_node_valid_settings() -> None:
    from merlin2_sailor.launcher import load_launch_file

    launch_folder = CONFIG.parent.parent / "launch"
    for launch in sorted(launch_folder.glob("*.yaml")):
        for spec in load_launch_file(launch).nodes:
            if spec.executable == "anchoring":
                settings = load_anchoring_settings(*spec.parameters)
                assert value_at(settings, ("core", "world_frame")) == "map", launch
