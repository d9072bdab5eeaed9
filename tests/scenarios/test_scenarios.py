"""Scenario files: what loads, and the clear errors on what cannot be used."""

import textwrap

import pytest

from pbp_drake.cli import main
from pbp_drake.scenarios import ScenarioError, load_scenario_file

VALID = """
scenario:
  method: pbp_continuous
  start: [0.0, 0.0]
  goals: [[1.0, 0.0]]
  dmp_duration: 1.0
  operator: !ObstacleRepulsion {speed: 1.0}
"""


def write(tmp_path, text):
    path = tmp_path / "scenario.yaml"
    path.write_text(textwrap.dedent(text))
    return path


def test_every_shipped_scenario_loads(repo):
    files = sorted((repo / "diagrams").glob("*.yaml"))
    assert files
    for path in files:
        assert load_scenario_file(path).scenario.method


def test_a_valid_file_loads(tmp_path):
    loaded = load_scenario_file(write(tmp_path, VALID))
    assert loaded.scenario.operator.speed == 1.0


@pytest.mark.parametrize("text, message", [
    (VALID.replace("speed:", "sped:"),
     r"scenario.operator: unknown key 'sped' \(did you mean 'speed'\?\); expected one of "),
    (VALID.replace("method:", "methd:"),
     r"scenario: unknown key 'methd' \(did you mean 'method'\?\); expected one of "),
    (VALID.replace("!ObstacleRepulsion", "!ObstacleRepulson"), "ObstacleRepulson"),
    (VALID.replace("pbp_continuous", "pbp_continous"),
     "scenario.method 'pbp_continous' is unknown.*did you mean 'pbp_continuous'"),
    (VALID + "  alpha: 1.5\n", r"scenario.alpha must lie in \[0, 1\], got 1.5"),
    (VALID + "  alpha: -0.5\n", r"scenario.alpha must lie in \[0, 1\], got -0.5"),
    (VALID.replace("goals: [[1.0, 0.0]]", "goals: []"), "scenario.goals"),
    (VALID.replace("goals: [[1.0, 0.0]]", "goals: [[1.0, .nan]]"), "scenario.goals"),
    (VALID.replace("start: [0.0, 0.0]\n  goals: [[1.0, 0.0]]\n",
                   "demonstration: !RecordedPath {times: [0, 1], positions: [[0, 0], [1, 0]]}\n"),
     "scenario.demonstration: demonstration has 2 samples; at least 3"),
    (VALID.replace("start: [0.0, 0.0]\n  goals: [[1.0, 0.0]]\n",
                   "demonstration: !RecordedPath {times: [0, 0.5, 1], "
                   "positions: [[0, 0], [.nan, 0], [1, 0]]}\n"),
     r"scenario.demonstration.positions\[1\]\[0\]: NaN is not a number here; expected a "
     "finite number"),
    (VALID.replace("!ObstacleRepulsion {speed: 1.0}",
                   "!ScriptedCommands {times: [0.0], commands: [[.nan, 0.0]]}"),
     r"scenario.operator.commands\[0\]\[0\]: NaN"),
    (VALID.replace("!ObstacleRepulsion {speed: 1.0}",
                   "!ScriptedCommands {times: [0.0], commands: [[.inf, 0.0]]}"),
     r"scenario.operator.commands\[0\]\[0\]: inf is infinite; expected a finite number"),
])
def test_bad_scenarios_name_the_field(tmp_path, text, message):
    with pytest.raises(ScenarioError, match=message):
        load_scenario_file(write(tmp_path, text))


def test_alpha_study_with_alpha_outside_unit_interval_is_refused(tmp_path, repo):
    text = (repo / "diagrams/toy_alpha_study.yaml").read_text()
    text = text.replace("alphas: [0.0, 0.1,", "alphas: [-0.2, 0.1,")
    with pytest.raises(ScenarioError, match=r"study.alphas has -0.2, outside \[0, 1\]"):
        load_scenario_file(write(tmp_path, text))


def test_cli_reports_bad_input_without_a_traceback(tmp_path, capsys, repo):
    assert main(["run", str(repo / "diagrams/toy_alpha_study.yaml"), "--method", "telop",
                 "--headless"]) == 2
    assert "method 'telop' is unknown" in capsys.readouterr().err
    assert main(["run", str(repo / "diagrams/toy_alpha_study.yaml"), "--scene", "nowhere",
                 "--headless"]) == 2
    assert "--scene 'nowhere' is not in this file's study" in capsys.readouterr().err
    bad = write(tmp_path, VALID.replace("speed:", "sped:"))
    assert main(["study", str(bad), "--output", str(tmp_path / "out")]) == 2
    assert "sped" in capsys.readouterr().err


def test_a_method_label_can_carry_the_arbitration_weight():
    from pbp_drake.scenarios import Scenario, with_method

    assert with_method(Scenario(), "fixed_alpha=0.3").alpha == 0.3
    assert with_method(Scenario(), "teleop").method == "teleop"
    for bad, message in [("fixed_alpha=2", "in \\[0, 1\\]"), ("teleop=0.5", "only fixed_alpha"),
                         ("fixed_alpha=half", "alpha must be a number in \\[0, 1\\]"),
                         # The weight left out: not the file's alpha in silence.
                         ("fixed_alpha=", "'fixed_alpha=': alpha must be a number"),
                         ("teleop=", "'teleop=': only fixed_alpha"),
                         ("fixed_alfa", "did you mean 'fixed_alpha'")]:
        with pytest.raises(ScenarioError, match=message):
            with_method(Scenario(), bad)


HSR = """
scenario:
  method: pbp_alternated
  duration: 60.0
  robot: !Hsr {{{robot}}}
  task: !MultiGoalReach {{}}
  operator: !VirtualParticipant {{}}
"""


@pytest.mark.parametrize("robot, message", [
    ("max_hand_acceleration: 0.0", "scenario.robot.max_hand_acceleration must be finite and "
                                   "positive"),
    ("max_hand_acceleration: -1.0", "scenario.robot.max_hand_acceleration must be finite"),
    ("max_hand_acceleration: .inf", "scenario.robot.max_hand_acceleration: inf is infinite; "
                                   "expected a finite number"),
    # 0.12 m/s at 0.001 m/s^2 takes 120 s, over the 60 s time limit.
    ("max_hand_acceleration: 0.001", r"max_hand_acceleration 0.001 m/s\^2 takes 120.0 s"),
    ("max_hand_speed: 0.0", "scenario.robot.max_hand_speed must be finite and positive"),
    ("max_hand_yaw_acceleration: -2.0", "scenario.robot.max_hand_yaw_acceleration must be "
                                        "finite and positive"),
    ("max_hand_speed: 0.1", "scenario.robot.max_hand_speed 0.1 m/s is below the task's "
                            "speed 0.12"),
])
def test_hand_over_limits_that_cannot_work_are_refused(tmp_path, robot, message):
    with pytest.raises(ScenarioError, match=message):
        load_scenario_file(write(tmp_path, HSR.format(robot=robot)))


@pytest.mark.parametrize("extra, message", [
    ("  control_period: .inf\n", "scenario.control_period: inf is infinite; expected a finite"),
    ("  control_period: 0.0\n", "scenario.control_period must be finite and positive"),
    ("  duration: .inf\n", "scenario.duration: inf is infinite; expected a finite number"),
    ("  duration: -1.0\n", "scenario.duration must be finite and positive"),
    ("  robot: {mass: 0.0}\n", "scenario.robot.mass must be finite and positive"),
    ("  robot: {time_step: 0.0}\n", "scenario.robot.time_step must be finite and positive"),
    ("  robot: {damping: -1.0}\n", "scenario.robot.damping must be finite and not negative"),
    ("  robot: {stiffness: .inf}\n", "scenario.robot.stiffness: inf is infinite"),
    ("  robot: {stiffness: 0.0}\n", "scenario.robot.stiffness must be finite and positive"),
    ("  obstacles: [{center: [.nan, 0.0], radius: 0.1}]\n",
     r"scenario.obstacles\[0\].center\[0\]: NaN is not a number here"),
    ("  obstacles: [{center: [0.5, 0.0], radius: .inf}]\n",
     r"scenario.obstacles\[0\].radius: inf is infinite"),
    ("  obstacles: [{center: [0.5, 0.0], radius: 0.0}]\n",
     r"scenario.obstacles\[0\] needs a finite center of dimension 2 and a finite positive"),
])
def test_numbers_that_are_not_finite_or_in_range_are_refused(tmp_path, extra, message):
    with pytest.raises(ScenarioError, match=message):
        load_scenario_file(write(tmp_path, VALID + extra))


@pytest.mark.parametrize("distance, message", [
    (".inf", "scenario.task.success_distance: inf is infinite; expected a finite number"),
    ("0.0", "scenario.task.success_distance must be finite and positive"),
    ("3.0", r"scenario.task.success_distance 3.0 m reaches the nearest object .* succeed at "
            "once"),
])
def test_a_success_distance_that_ends_the_task_at_once_is_refused(tmp_path, distance, message):
    text = HSR.format(robot="").replace("!MultiGoalReach {}",
                                        f"!MultiGoalReach {{success_distance: {distance}}}")
    with pytest.raises(ScenarioError, match=message):
        load_scenario_file(write(tmp_path, text))


@pytest.mark.parametrize("old, new, message", [
    ("name: scene_2", "name: scene_1", r"study.scenes\[1\]: the name 'scene_1' is taken"),
    ("{center: [0.5, 0.4], radius: 0.12}", "{center: [0.5, 0.4, 0.0], radius: 0.12}",
     r"study.scenes\[1\].obstacles\[0\] needs a finite center of dimension 2"),
    ("{center: [0.5, 0.4], radius: 0.12}", "{center: [0.5, .nan], radius: 0.12}",
     r"study.scenes\[1\].obstacles\[0\].center\[1\]: NaN is not a number here"),
])
def test_alpha_study_scenes_are_checked_when_the_file_loads(tmp_path, repo, old, new, message):
    text = (repo / "diagrams/toy_alpha_study.yaml").read_text()
    assert old in text
    path = tmp_path / "study.yaml"
    path.write_text(text.replace(old, new))
    with pytest.raises(ScenarioError, match=message):
        load_scenario_file(path)
