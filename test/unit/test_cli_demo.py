"""``sailor demo``: its output folder is emptied of a previous run's files, never of anyone else's."""

from __future__ import annotations

import json

import pytest

from merlin2_sailor.cli.demo_command import prepare_output
from merlin2_sailor.cli.main import build_parser
from merlin2_sailor.errors import ConfigurationError


def test_a_new_folder_is_made_and_returned_absolute(tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    folder = prepare_output(tmp_path.relative_to(tmp_path) / "reports" / "demo")
    assert folder.is_absolute() and folder.is_dir() and folder == tmp_path / "reports" / "demo"


def test_a_previous_runs_files_are_removed_so_the_robot_starts_knowing_nothing(tmp_path) -> None:
    (tmp_path / "report" / "frames").mkdir(parents=True)
    (tmp_path / "report" / "summary.md").write_text("old")
    (tmp_path / "anchoring").mkdir()
    (tmp_path / "knowledge.db").write_bytes(b"old")
    (tmp_path / "ground_truth.json").write_text("{}")
    assert prepare_output(tmp_path) == tmp_path.resolve()
    assert list(tmp_path.iterdir()) == []


def test_a_folder_with_other_files_is_refused_and_left_alone(tmp_path) -> None:
    (tmp_path / "thesis.tex").write_text("precious")
    (tmp_path / "knowledge.db").write_bytes(b"old")
    with pytest.raises(ConfigurationError, match="thesis.tex"):
        prepare_output(tmp_path)
    assert (tmp_path / "thesis.tex").read_text() == "precious" and (tmp_path / "knowledge.db").exists()


def test_a_file_is_not_an_output_folder(tmp_path) -> None:
    (tmp_path / "out").write_text("")
    with pytest.raises(ConfigurationError, match="not a folder"):
        prepare_output(tmp_path / "out")


def test_the_command_is_registered_with_its_options() -> None:
    arguments = build_parser().parse_args(["demo", "--output", "somewhere", "--grace-period", "5"])
    assert str(arguments.output) == "somewhere" and arguments.grace_period == 5.0


def test_the_scenario_options_are_registered() -> None:
    parser = build_parser()
    arguments = parser.parse_args(["demo", "--all-scenarios", "--seeds", "0,1,2", "--matcher", "network",
                                   "--deadline", "200"])
    assert arguments.all_scenarios and arguments.seeds == [0, 1, 2] and arguments.matcher == "network"
    assert arguments.deadline == 200.0 and arguments.scenario is None
    arguments = parser.parse_args(["demo", "--scenario", "removed", "--scenario", "swapped", "--seed", "4"])
    assert arguments.scenario == ["removed", "swapped"] and arguments.seed == 4 and arguments.matcher is None


@pytest.mark.parametrize("options", [
    ["--scenario", "removed", "--all-scenarios"],
    ["--seed", "1", "--seeds", "1,2"],
    ["--seeds", "a,b"],
    ["--seeds", "-1"],
    ["--seed", "-3"],
    ["--seeds", ","],
    ["--matcher", "magic"],
])
def test_contradictory_or_bad_scenario_options_are_refused(options, capsys) -> None:
    with pytest.raises(SystemExit):
        build_parser().parse_args(["demo", *options])


def test_seeds_without_a_scenario_are_refused(tmp_path) -> None:
    arguments = build_parser().parse_args(["demo", "--seeds", "1,2", "--output", str(tmp_path / "out")])
    with pytest.raises(ConfigurationError, match="--seeds runs scenarios"):
        arguments.run(arguments)
    assert not (tmp_path / "out").exists()


def test_list_scenarios_prints_each_with_its_description(capsys) -> None:
    arguments = build_parser().parse_args(["demo", "--list-scenarios"])
    assert arguments.run(arguments) == 0
    lines = capsys.readouterr().out.splitlines()
    names = [line.split()[0] for line in lines]
    assert names[0] == "default" and {"removed", "swapped", "twin_moved", "crowded_shelf"} <= set(names)
    assert all(len(line.split(maxsplit=1)) == 2 for line in lines)  # a description on every line


def test_an_unknown_scenario_is_an_error_before_anything_runs(tmp_path) -> None:
    arguments = build_parser().parse_args(["demo", "--scenario", "nope", "--output", str(tmp_path / "out")])
    with pytest.raises(ConfigurationError, match="no scenario 'nope'"):
        arguments.run(arguments)
    assert not (tmp_path / "out").exists()


def test_a_scenario_folder_from_an_earlier_run_is_emptied_too(tmp_path) -> None:
    (tmp_path / "runs" / "removed-seed0-rules").mkdir(parents=True)
    (tmp_path / "scenarios.json").write_text("{}")
    (tmp_path / "scenarios.md").write_text("old")
    assert prepare_output(tmp_path) == tmp_path.resolve() and list(tmp_path.iterdir()) == []


def test_a_run_gets_the_scenario_world_seed_matcher_data_folder_and_domain(tmp_path) -> None:
    from merlin2_sailor_demos.scenario_runner import RunOptions, demo_launch, effective_parameter

    spec = demo_launch(tmp_path, "worlds/scenarios/removed.yaml", RunOptions(seed=3, matcher="network", domain=42))
    assert effective_parameter(spec, "world", "world_file") == "worlds/scenarios/removed.yaml"
    assert effective_parameter(spec, "world", "seed") == 3
    assert effective_parameter(spec, "mission_demo", "world_file") == "worlds/scenarios/removed.yaml"
    assert effective_parameter(spec, "anchoring", "matcher") == "network"
    assert effective_parameter(spec, "anchoring", "state_folder") == str(tmp_path / "anchoring")
    assert effective_parameter(spec, "mission_demo", "report_folder") == str(tmp_path / "report")
    assert spec.environment["ROS_DOMAIN_ID"] == "42" and spec.environment["SAILOR_DATA"] == str(tmp_path)
    default = demo_launch(tmp_path, None, RunOptions())
    # Without overrides the launch file's own values stand: the matcher comes from config/anchoring.yaml.
    assert effective_parameter(default, "world", "world_file") == "worlds/house.yaml"
    assert effective_parameter(default, "anchoring", "matcher") in ("rules", "network")
    assert effective_parameter(default, "world", "seed") == 0  # config/world.yaml's
    assert "ROS_DOMAIN_ID" not in default.environment


def test_parameters_go_only_to_nodes_the_launch_has(tmp_path) -> None:
    from merlin2_sailor_demos.scenario_runner import RunOptions, demo_launch, with_parameters

    with pytest.raises(ConfigurationError, match=r"no node \['nobody'\]"):
        with_parameters(demo_launch(tmp_path, None, RunOptions()), {"nobody": {"x": 1}})


@pytest.mark.parametrize("options", [["--soak", "0"], ["--soak", "x"], ["--soak", "3", "--all-scenarios"]])
def test_bad_soak_options_are_refused(options) -> None:
    with pytest.raises(SystemExit):
        build_parser().parse_args(["demo", *options])


def test_a_soak_runs_the_demo_and_every_scenario_in_turn_each_with_the_next_seed(tmp_path, monkeypatch,
                                                                                capsys) -> None:
    from merlin2_sailor_demos import scenario_runner
    from merlin2_sailor_demos.report.scenario_table import HANG, ScenarioRun
    from merlin2_sailor_demos.report.verdict import Verdict
    from merlin2_sailor_demos.scenarios import all_scenarios

    ran = []

    def fake_run(entry, folder, options, matcher, echo=None, stop=None):  # noqa: ANN001, ANN202
        ran.append((entry.name, options.seed))
        folder.mkdir(parents=True)
        if len(ran) == 3:
            (folder / "launch.log").write_text("[mission_demo] WARN: the result of explore(kitchen) was lost on the "
                                               "way; asked for it again (1 time(s))\n")
            return ScenarioRun(entry.name, options.seed, matcher, None, ending=HANG, wall_seconds=420.0,
                               folder=str(folder))
        return ScenarioRun(entry.name, options.seed, matcher, Verdict("found", True), wall_seconds=10.0 * len(ran),
                           folder=str(folder))

    monkeypatch.setattr(scenario_runner, "run_scenario", fake_run)
    names = [entry.name for entry in all_scenarios()]
    count = len(names) + 2
    arguments = build_parser().parse_args(["demo", "--soak", str(count), "--seed", "5", "--output",
                                           str(tmp_path / "out")])
    assert arguments.run(arguments) == 1  # one run hung
    assert ran == [(names[index % len(names)], 5 + index) for index in range(count)]
    text = capsys.readouterr().out
    assert "hangs (still running at the deadline)" in text
    soak = json.loads((tmp_path / "out" / "soak.json").read_text())
    assert (soak["runs"], soak["right"], soak["hangs"], soak["lost_results_recovered"]) == (count, count - 1, 1, 1)
    assert soak["slowest"]["scenario"] == names[2]
    assert (tmp_path / "out" / "soak.md").read_text().startswith("# Soak\n\n| figure | value |")
