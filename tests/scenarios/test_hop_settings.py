"""The scenario's `hop` section: its defaults are the published constants and reach the
systems, a changed value reaches them too, and a value that cannot be used is refused
naming its field; the methods and the estimator that read it are refused where they
cannot run."""

import math
import textwrap

import pytest

from pbp_drake import cli
from pbp_drake.builder import build_diagram, find_system
from pbp_drake.core.hindsight_optimization import HopSettings
from pbp_drake.scenarios import ScenarioError, load_scenario_file

HSR = """
scenario:
  robot: !Hsr {}
  task: {}
  control_period: 0.03
  operator: !VirtualParticipant {}
"""


def scenario_file(tmp_path, extra):
    path = tmp_path / "scenario.yaml"
    path.write_text(textwrap.dedent(HSR) + textwrap.indent(textwrap.dedent(extra), "  "))
    return path


def test_the_defaults_are_the_published_constants():
    settings = HopSettings()
    assert (settings.translation_gain, settings.translation_switch_distance,
            settings.translation_constant) == (2.25, 0.07, 0.2)
    assert (settings.rotation_gain, settings.rotation_switch_angle,
            settings.rotation_constant, settings.rotation_weight) == (
        0.20, math.pi / 32, 0.01, 0.07)
    assert (settings.translation_divisor, settings.rotation_divisor) == (40.0, 0.05)
    assert (settings.translation_fade_distance, settings.rotation_fade_angle) == (
        0.02, math.pi / 12)
    assert (settings.cost_time_step, settings.max_probability,
            settings.blending_threshold) == (0.1, 0.99, 0.4)
    assert settings.assistance is True


def test_a_file_without_the_section_builds_the_defaults_and_a_value_reaches_the_systems(
        tmp_path):
    default = load_scenario_file(scenario_file(tmp_path, "method: hop\n")).resolved
    diagram = build_diagram(default)
    assert find_system(diagram, "goal_estimator").settings == HopSettings()
    assert find_system(diagram, "assistance").settings == HopSettings()
    changed = load_scenario_file(scenario_file(
        tmp_path, "method: predict_then_assist\nhop: {max_probability: 0.95, "
                  "blending_threshold: 0.2}\n")).resolved
    diagram = build_diagram(changed)
    assert find_system(diagram, "goal_estimator").settings.max_probability == 0.95
    assert find_system(diagram, "assistance").settings.blending_threshold == 0.2


@pytest.mark.parametrize("extra, message", [
    ("hop: {max_probability: 1.5}", "scenario.hop: max_probability must lie in (0, 1]"),
    ("hop: {max_probability: 0.0}", "scenario.hop: max_probability must lie in (0, 1]"),
    ("hop: {blending_threshold: 1.0}", "scenario.hop: blending_threshold must lie in [0, 1)"),
    ("hop: {translation_divisor: 0.0}", "scenario.hop: translation_divisor must be positive"),
    ("hop: {rotation_weight: -0.07}", "scenario.hop: rotation_weight must be positive"),
    ("hop: {cost_time_step: .nan}", "scenario.hop.cost_time_step: NaN is not a number"),
    ("hop: {translation_gain: .inf}", "scenario.hop.translation_gain: inf is infinite"),
    ("hop: {assistance: 1}", "scenario.hop.assistance: got 1; expected true or false"),
    ("hop: {assistance: 0.5}", "scenario.hop.assistance: got 0.5; expected true or false"),
    ("hop: {max_probabilty: 0.9}", "scenario.hop: unknown key 'max_probabilty' (did you "
                                   "mean 'max_probability'?)"),
])
def test_bad_values_are_refused_naming_the_field(tmp_path, extra, message):
    with pytest.raises(ScenarioError) as raised:
        load_scenario_file(scenario_file(tmp_path, f"method: hop\n{extra}\n"))
    assert message in str(raised.value)


def test_assistance_is_true_or_false_from_python_too():
    with pytest.raises(ValueError, match="assistance must be true or false, got 0"):
        HopSettings(assistance=0)


def test_the_baselines_are_refused_on_the_2d_robot(tmp_path):
    path = tmp_path / "toy.yaml"
    path.write_text("scenario:\n  method: hop\n  start: [0.0, 0.0]\n  goals: [[1.0, 0.0]]\n"
                    "  dmp_duration: 1.0\n")
    with pytest.raises(ScenarioError, match="scenario.method hop assists toward the HSR "
                                            "tasks' goals"):
        load_scenario_file(path)


def test_the_maxent_command_estimator_builds_in_pbps_loop(tmp_path):
    resolved = load_scenario_file(scenario_file(
        tmp_path, "goal_estimator: {method: maxent_command, margin: 0.2, hold_steps: 3}\n"
                  "hop: {cost_time_step: 0.05}\n")).resolved
    estimator = find_system(build_diagram(resolved), "goal_estimator")
    assert (type(estimator).__name__, estimator.margin, estimator.hold_steps) == (
        "MaxEntGoalEstimator", 0.2, 3)
    assert estimator.settings.cost_time_step == 0.05


OLD_NAME = "method 'policy_blending' is now called 'predict_then_assist'"


def test_the_old_name_of_predict_then_assist_is_refused_in_a_file(tmp_path, run_refused):
    code, err, _ = run_refused(scenario_file(tmp_path, "method: policy_blending\n"))
    assert code == 2 and "Traceback" not in err
    assert f"scenario.{OLD_NAME}" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("arguments", [
    ["run", "{file}", "--headless", "--method", "policy_blending"],
    ["study", "{file}", "--methods", "hop,policy_blending", "--trials", "1",
     "--output", "{output}"],
])
def test_the_old_name_is_refused_on_the_command_line_and_nothing_is_written(
        tmp_path, run_refused, capsys, arguments):
    path = scenario_file(tmp_path, "method: hop\n")
    output = tmp_path / "study"
    code = cli.main([argument.format(file=path, output=output) for argument in arguments])
    err = capsys.readouterr().err
    assert code == 2 and OLD_NAME in err and len(err.strip().splitlines()) == 1
    assert not output.exists()
