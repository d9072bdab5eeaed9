"""The command line's changes to a scenario file's fields (`--set FIELD=VALUE`,
`--scenario-text YAML` and their shorthands): merged onto the file, checked as the file is,
refused in one line naming the field, and recorded in a study's study.json."""

import json

import pytest
from pydrake.common.yaml import yaml_dump_typed

from pbp_drake.cli import main
from pbp_drake.commands.study import default_output
from pbp_drake.scenarios import Keyboard, ScenarioError, load_scenario_file
from pbp_drake.scenarios.overrides import ScenarioOverrides, merged, parse_setting

TASK = "diagrams/hsr_reach.yaml"
TOY = "diagrams/toy_alt_vs_cont.yaml"


def test_a_setting_is_a_dotted_path_and_a_yaml_value():
    assert parse_setting("goal_estimator.method=nearest") == (["goal_estimator", "method"],
                                                              "nearest")
    assert parse_setting("control_period=0.02") == (["control_period"], 0.02)
    assert parse_setting("task.object_count=[5, 5]") == (["task", "object_count"], [5, 5])
    assert parse_setting("operator=!Keyboard {}") == (["operator"], {"_tag": "!Keyboard"})


@pytest.mark.parametrize("setting", ["seed", "=3", "a..b=1", "seed=[1"])
def test_a_setting_that_is_not_field_equals_value_is_refused(setting):
    with pytest.raises(ScenarioError, match="--set"):
        ScenarioOverrides((setting,))


def test_mappings_merge_key_by_key_and_another_tag_replaces():
    base = {"operator": {"_tag": "!Keyboard", "speed": 0.2, "hold_time": 0.6}, "seed": 1}
    assert merged(base, {"operator": {"speed": 0.3}}) == {
        "operator": {"_tag": "!Keyboard", "speed": 0.3, "hold_time": 0.6}, "seed": 1}
    # The same tag keeps the file's settings; another replaces them.
    assert merged(base, {"operator": {"_tag": "!Keyboard"}}) == base
    assert merged(base, {"operator": {"_tag": "!Gamepad"}})["operator"] == {"_tag": "!Gamepad"}
    assert merged({"a": [1, 2]}, {"a": [3]}) == {"a": [3]}


def test_the_settings_change_the_scenario_and_its_study(repo):
    loaded = load_scenario_file(repo / TASK, ScenarioOverrides(
        ("goal_estimator.method=nearest", "control_period=0.02", "study.trials=3"),
        "{seed: 7, operator: !Keyboard {}, goal_estimator: {temperature: 0.5}}"))
    scenario = loaded.scenario
    assert scenario.goal_estimator.method == "nearest"
    assert scenario.goal_estimator.temperature == 0.5
    assert scenario.goal_estimator.margin == 0.1  # the file's, kept
    assert scenario.control_period == 0.02 and scenario.seed == 7
    assert isinstance(scenario.operator, Keyboard)
    assert loaded.study.trials == 3
    # Field by field: resolve keeps a copy, and Drake's config structs compare by identity.
    assert yaml_dump_typed(loaded.resolved.scenario) == yaml_dump_typed(scenario)


def test_the_scenario_text_changes_the_study_too(repo):
    loaded = load_scenario_file(repo / TASK, ScenarioOverrides((), "{seed: 7, study: {trials: 3}}"))
    assert loaded.scenario.seed == 7 and loaded.study.trials == 3
    assert loaded.study.methods == ["pbp_alternated", "pbp_continuous", "teleop"]  # the file's


@pytest.mark.parametrize("argv, message", [
    (["--set", "goal_estimator.methd=nearest"],
     "pbp-drake: diagrams/hsr_reach.yaml with --set goal_estimator.methd=nearest: "
     "scenario.goal_estimator: unknown key 'methd' (did you mean 'method'?)"),
    (["--set", "control_period=fast"],
     "with --set control_period=fast: scenario.control_period: got 'fast'; expected a number"),
    (["--scenario-text", "{seed: [1}"], "pbp-drake: --scenario-text: not YAML"),
    (["--scenario-text", "3"], "pbp-drake: --scenario-text: expected a mapping"),
    (["--scenario-text", "{seed: 1, seed: 2}"],
     "pbp-drake: --scenario-text: line 1: duplicate key 'seed'"),
    (["--seed", "4", "--set", "contrl_period=0.02"],
     "with --seed 4 --set contrl_period=0.02: scenario: unknown key 'contrl_period' "
     "(did you mean 'control_period'?)"),
])
def test_a_bad_override_exits_2_with_one_line_naming_the_field(repo, capsys, monkeypatch,
                                                                argv, message):
    monkeypatch.chdir(repo)
    assert main(["run", TASK, "--no-meshcat", *argv]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.count("\n") == 1 and message in captured.err, captured.err


def test_the_same_override_is_refused_by_study_before_anything_is_written(repo, tmp_path,
                                                                           capsys):
    output = tmp_path / "study"
    assert main(["study", str(repo / TASK), "--output", str(output), "--set",
                 "goal_estimator.methd=nearest"]) == 2
    assert "did you mean 'method'?" in capsys.readouterr().err
    assert not output.exists()


def test_a_study_is_refused_a_person_at_the_keys(repo, tmp_path, capsys):
    assert main(["study", str(repo / TASK), "--output", str(tmp_path / "s"), "--set",
                 "operator=!Keyboard {}"]) == 2
    assert "a study runs unattended" in capsys.readouterr().err


def test_a_study_folder_defaults_to_the_scenario_and_its_methods(repo):
    task = load_scenario_file(repo / TASK)
    assert str(default_output(TASK, task)) == (
        "outputs/hsr_reach-pbp_alternated-pbp_continuous-teleop")
    assert str(default_output(TASK, task, "hop,teleop")) == "outputs/hsr_reach-hop-teleop"
    assert str(default_output(TOY, load_scenario_file(repo / TOY))) == "outputs/toy_alt_vs_cont"


@pytest.mark.slow  # one trial of the reaching task: about 5 s
def test_a_study_records_its_overrides_and_report_names_them(repo, tmp_path, capsys):
    output = tmp_path / "study"
    settings = ["task.object_count=[2, 2]", "goal_estimator.method=nearest"]
    assert main(["study", str(repo / TASK), "--methods", "teleop", "--trials", "1",
                 "--output", str(output), "--set", settings[0], "--set", settings[1]]) == 0
    study = json.loads((output / "study.json").read_text())
    assert study["overrides"] == {"set": settings, "scenario_text": None}
    assert study["scenario_content"]["goal_estimator"]["method"] == "nearest"
    markdown = tmp_path / "results.md"
    assert main(["report", str(output), "--markdown", str(markdown)]) == 0
    assert ("--set 'task.object_count=[2, 2]' --set goal_estimator.method=nearest"
            in markdown.read_text())


@pytest.mark.slow  # two trials of the reaching task: a few seconds
def test_a_study_of_many_goals_draws_each_trials_grid_from_its_seed(repo, tmp_path):
    output = tmp_path / "study"
    assert main(["study", str(repo / TASK), "--goals", "30", "--methods", "teleop",
                 "--trials", "2", "--output", str(output)]) == 0
    study = json.loads((output / "study.json").read_text())
    assert study["overrides"]["set"] == ["task.grid_objects=30"]
    trials = [json.loads((output / "trials" / "teleop" / f"seed_{seed}.json").read_text())
              for seed in (10_000, 10_001)]
    assert [len(trial["objects"]) for trial in trials] == [30, 30]
    assert trials[0]["objects"] != trials[1]["objects"]  # each trial's grid from its seed


def test_a_python_user_overrides_a_file_with_the_packages_own_names(repo):
    import pbp_drake

    loaded = pbp_drake.load_scenario_file(repo / TASK, pbp_drake.ScenarioOverrides(
        settings=("goal_estimator.method=nearest", "control_period=0.02")))
    assert loaded.scenario.goal_estimator.method == "nearest"
    assert loaded.scenario.control_period == 0.02
