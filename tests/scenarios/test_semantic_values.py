"""Values of the right type that a scenario cannot use as written: each is refused by
`run` and `study` in one line naming its field, exit 2, where it ran and did something else
(exit 0) or ended in a traceback."""

import json
import pathlib

import pytest

from pbp_drake import cli
from pbp_drake.commands import run_page

DIAGRAMS = pathlib.Path(__file__).resolve().parents[2] / "diagrams"


def edited(tmp_path, file, old, new):
    """The shipped `file` with its first `old` replaced by `new`, written to `tmp_path`."""
    text = (DIAGRAMS / file).read_text()
    assert old in text, old
    path = tmp_path / file
    path.write_text(text.replace(old, new, 1))
    return path


def assert_refused(code, err, *words):
    """A refusal: exit 2, one line naming each of `words`."""
    assert code == 2, err
    assert "Traceback" not in err, err
    assert err.startswith("pbp-drake: ") and err.count("\n") == 1, err
    for word in words:
        assert word in err, (word, err)


def test_a_duration_shorter_than_one_control_tick_is_refused(tmp_path, run_refused):
    # It ran no tick at all, exit 0: the robot stood at its start.
    path = edited(tmp_path, "toy_alt_vs_cont.yaml", "duration: 3.0", "duration: 0.004")
    code, err, _ = run_refused(path)
    assert_refused(code, err, "scenario.duration 0.004 s", "scenario.control_period 0.01 s")


def test_study_refuses_a_duration_shorter_than_one_control_tick(tmp_path, capsys):
    code = cli.main(["study", str(DIAGRAMS / "toy_alt_vs_cont.yaml"), "--output",
                     str(tmp_path / "study"), "--set", "duration=0.004"])
    assert_refused(code, capsys.readouterr().err, "scenario.duration 0.004 s", "--set")
    assert not (tmp_path / "study").exists()


@pytest.mark.parametrize("tolerance", ["0.0", "-0.01"])
def test_study_refuses_an_alt_vs_cont_goal_tolerance_no_run_can_meet(tmp_path, capsys,
                                                                      tolerance):
    # It ran both modes and reported that neither reached the goal, exit 0.
    code = cli.main(["study", str(DIAGRAMS / "toy_alt_vs_cont.yaml"), "--output",
                     str(tmp_path / "study"), "--set", f"study.goal_tolerance={tolerance}"])
    assert_refused(code, capsys.readouterr().err, "study.goal_tolerance must be positive")
    assert not (tmp_path / "study").exists()


def test_study_refuses_an_alpha_given_twice(tmp_path, capsys):
    # The summary keys each alpha's results by it: the second run overwrote the first's,
    # and the study reported one alpha fewer, exit 0.
    code = cli.main(["study", str(DIAGRAMS / "toy_alpha_study.yaml"), "--output",
                     str(tmp_path / "study"), "--set", "study.alphas=[0.3, 0.5, 0.5]"])
    assert_refused(code, capsys.readouterr().err, "study.alphas has 0.50 twice")
    assert not (tmp_path / "study").exists()


def test_alpha_study_refuses_a_goal_the_demonstration_does_not_end_at(tmp_path, capsys):
    # Explicit arbitration played the demonstration to (1, 0) and every alpha was reported
    # short of the goal (1, 0.3), which PBP's DMPs reached, exit 0.
    code = cli.main(["study", str(DIAGRAMS / "toy_alpha_study.yaml"), "--output",
                     str(tmp_path / "study"), "--set", "goals=[[1.0, 0.3]]"])
    assert_refused(code, capsys.readouterr().err, "scenario.goals [[1.0, 0.3]]",
                   "scenario.demonstration ends, [1.0, 0.0]")
    assert not (tmp_path / "study").exists()


@pytest.mark.slow
def test_alphas_alike_to_two_decimals_are_each_named_by_all_their_digits(tmp_path, capsys):
    # They were named by two decimals: 0.501's results overwrote 0.5's, and 0.125 was
    # filed and tabled as 0.12.
    output = tmp_path / "study"
    assert cli.main(["study", str(DIAGRAMS / "toy_alpha_study.yaml"), "--output",
                     str(output), "--set", "study.alphas=[0.125, 0.5, 0.501]"]) == 0
    summary = json.loads((output / "summary.json").read_text())
    for scene in summary["scenes"]:
        for results in scene["by_operator_speed"].values():
            assert list(results["fixed_alpha"]) == ["0.125", "0.50", "0.501"]
    markdown = tmp_path / "alphas.md"
    assert cli.main(["report", str(output), "--markdown", str(markdown)]) == 0
    assert "| alpha 0.125 | alpha 0.50 | alpha 0.501 |" in markdown.read_text()


@pytest.mark.parametrize("setting, words", [
    # Each ended in a RuntimeError from Drake with a traceback, exit 1.
    ("simulator.integration_scheme=runge_kuta3",
     ["scenario.simulator.integration_scheme 'runge_kuta3' is unknown",
      "did you mean 'runge_kutta3'?"]),
    ("simulator.max_step_size=-0.1", ["scenario.simulator.max_step_size", "positive"]),
    ("simulator.start_time=5.0", ["scenario.simulator.start_time 5 s", "expected 0"]),
    # Ran 1 s earlier than the operator's script and the time limit said, exit 0.
    ("simulator.start_time=-1.0", ["scenario.simulator.start_time -1 s", "expected 0"]),
    # Taken as 0 (as fast as possible) without a word.
    ("simulator.target_realtime_rate=-1.0",
     ["scenario.simulator.target_realtime_rate", "not negative"]),
])
def test_a_simulator_setting_drake_cannot_run_as_written_is_refused(tmp_path, capsys,
                                                                     setting, words):
    code = cli.main(["run", str(DIAGRAMS / "toy_alt_vs_cont.yaml"), "--headless", "--set",
                     setting])
    assert_refused(code, capsys.readouterr().err, *words)


@pytest.mark.parametrize("times", ["[1.0, 0.5]", "[0.5, 0.5]"])
def test_scripted_commands_whose_times_do_not_increase_are_refused(tmp_path, capsys, times):
    # The operator refused them when the diagram was built: a ValueError, a traceback.
    code = cli.main(["run", str(DIAGRAMS / "toy_alt_vs_cont.yaml"), "--headless", "--set",
                     f"operator=!ScriptedCommands {{times: {times}, "
                     "commands: [[0.0, 1.0], [0.0, 0.0]]}"])
    assert_refused(code, capsys.readouterr().err, f"scenario.operator.times {times}",
                   "increase strictly")


@pytest.mark.parametrize("file, operator, words", [
    ("hsr_reach.yaml", "!Gamepad {dead_zone: 1.0}",
     "scenario.operator.dead_zone must be in [0, 1), not 1.0"),
    ("hsr_grasp.yaml", "!Gamepad {dead_zone: 1.5}",
     "scenario.operator.dead_zone must be in [0, 1), not 1.5"),
    # The grasping task's pose operators divide by them.
    ("hsr_grasp.yaml", "!Keyboard {rotation_speed: 0.0}",
     "scenario.operator.rotation_speed must be finite and positive"),
    ("hsr_grasp.yaml", "!Keyboard {hold_time: 0.0}",
     "scenario.operator.hold_time must be finite and positive"),
])
def test_a_person_operator_its_system_refuses_is_refused_before_the_page_opens(
        monkeypatch, capsys, file, operator, words):
    # The operator system refused it as the diagram was built, with a traceback.
    def no_page(*args, **kwargs):
        raise AssertionError("the file was accepted and Meshcat started")

    monkeypatch.setattr(run_page, "Meshcat", no_page)
    code = cli.main(["run", str(DIAGRAMS / file), "--set", f"operator={operator}"])
    assert_refused(code, capsys.readouterr().err, words)


def test_a_given_obstacle_start_on_the_robot_is_refused(tmp_path, run_refused):
    # Drawn obstacles keep obstacle_spacing from the robot's base; a given one on it ran
    # the trial in collision from the start, exit 1 as a failed task.
    path = edited(tmp_path, "hsr_wall.yaml", "obstacle_starts: [[1.1, -0.2],",
                  "obstacle_starts: [[0.2, -0.2],")
    code, err, _ = run_refused(path)
    assert_refused(code, err, "scenario.task.obstacle_starts[0] [0.2, -0.2] stands 0.28 m",
                   "obstacle_spacing 0.45 m")


def test_an_obstacle_repulsion_pushing_toward_the_obstacle_is_refused(tmp_path, capsys):
    # A negative speed pushed the robot into the obstacle it is to keep it from, exit 0.
    code = cli.main(["run", str(DIAGRAMS / "toy_alpha_study.yaml"), "--headless", "--set",
                     "operator.speed=-1.0"])
    assert_refused(code, capsys.readouterr().err,
                   "scenario.operator.speed must be finite and not negative, got -1.0")
