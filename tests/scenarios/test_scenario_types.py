"""A file's scenario is a 2-D scene (`PointScenario`) or a robot task (`TaskScenario`),
chosen by its robot's tag; each type holds its own fields, and a field of the other one is
refused saying where it belongs, through `pbp-drake run`."""

import dataclasses
import pathlib

import numpy as np
import pytest
from pydrake.common.yaml import yaml_dump_typed

from pbp_drake.scenarios import (
    Arm, Hsr, PointRobot, PointScenario, Scenario, ScenarioError, TaskScenario,
    TaskScenarioFile, load_scenario_file, resolve)

DIAGRAMS = pathlib.Path(__file__).resolve().parents[2] / "diagrams"


@pytest.mark.parametrize("file, kind, robot", [
    ("toy_alt_vs_cont.yaml", PointScenario, PointRobot),
    ("hsr_reach.yaml", TaskScenario, Hsr),
    ("arm_reach.yaml", TaskScenario, Arm),
])
def test_the_robots_tag_chooses_the_scenarios_type(file, kind, robot):
    scenario = load_scenario_file(DIAGRAMS / file).scenario
    assert type(scenario) is kind and type(scenario.robot) is robot


def _refusal(tmp_path, run_refused, file, old, new):
    text = (DIAGRAMS / file).read_text()
    assert old in text, old
    path = tmp_path / file
    path.write_text(text.replace(old, new, 1))
    code, err, _ = run_refused(path)
    assert code == 2, err
    assert len(err.strip().splitlines()) == 1, err
    return err.strip()


@pytest.mark.parametrize("file, old, new, message", [
    # A task in a 2-D scene...
    ("toy_alt_vs_cont.yaml", "  start: [0.0, 0.0]", "  start: [0.0, 0.0]\n  task: {}",
     "scenario: unknown key 'task' (a robot task's field: give robot: !Hsr {...} or "
     "!Arm {...}); expected one of "),
    # ...a seed in a 2-D scene, which draws nothing from it...
    ("toy_alt_vs_cont.yaml", "  start: [0.0, 0.0]", "  start: [0.0, 0.0]\n  seed: 3",
     "scenario: unknown key 'seed' (a robot task's field: give robot: !Hsr {...} or "
     "!Arm {...}); expected one of "),
    # ...goals in a robot task, which draws its own...
    ("hsr_reach.yaml", "  seed: 0", "  seed: 0\n  goals: [[1.0, 0.0, 0.7]]",
     "scenario: unknown key 'goals' (a 2-D scene's field: a robot task draws its goals, the "
     "objects, from its task and starts where the robot stands); expected one of "),
    # ...a person's keyboard on the point robot, named with the operators it takes.
    ("toy_alt_vs_cont.yaml", "  operator: !SinusoidalStep", "  operator: !Keyboard",
     "scenario.operator: the tag !Keyboard is unknown; expected one of !NoOperator, "
     "!ObstacleRepulsion, !SinusoidalStep, !ScriptedCommands"),
    # A tag on a field of one type, which Drake reads untagged: the tag is named.
    ("toy_alt_vs_cont.yaml", "  robot: {mass", "  robot: !PointRobot {mass",
     "scenario.robot: PointRobot is written without a tag; drop !PointRobot"),
    # A robot that is no mapping, in a file with a task: the robot is named.
    ("hsr_reach.yaml", "  robot: !Hsr", "  robot: 3\n  _robot: !Hsr",
     "scenario.robot: got 3; expected a mapping, tagged with one of !Hsr, !Arm "
     "(untagged: Hsr)"),
])
def test_a_field_of_the_other_type_says_where_it_belongs(tmp_path, run_refused, file, old,
                                                         new, message):
    assert message in _refusal(tmp_path, run_refused, file, old, new)


def test_a_robot_task_written_by_yaml_dump_typed_loads_again(tmp_path):
    # Drake writes the first variant of a field untagged: the HSR's `robot: {...}`.
    loaded = load_scenario_file(DIAGRAMS / "hsr_reach.yaml")
    path = tmp_path / "dumped.yaml"
    path.write_text(yaml_dump_typed(TaskScenarioFile(scenario=loaded.scenario)))
    assert "!Hsr" not in path.read_text()
    again = load_scenario_file(path)
    assert type(again.scenario) is TaskScenario and type(again.scenario.robot) is Hsr
    assert yaml_dump_typed(again.scenario) == yaml_dump_typed(loaded.scenario)
    np.testing.assert_array_equal(again.resolved.goals, loaded.resolved.goals)


def test_a_scenario_made_in_python_with_the_other_kinds_operator_is_refused():
    toy = load_scenario_file(DIAGRAMS / "toy_alt_vs_cont.yaml").scenario
    reach = load_scenario_file(DIAGRAMS / "hsr_reach.yaml").scenario
    with pytest.raises(ScenarioError, match=r"scenario.operator !VirtualParticipant does not "
                       r"drive a PointScenario; expected one of !NoOperator, "):
        resolve(dataclasses.replace(toy, operator=reach.operator))
    with pytest.raises(ScenarioError, match=r"scenario.operator !SinusoidalStep does not "
                       r"drive a TaskScenario; expected one of !NoOperator, !Keyboard, "):
        resolve(dataclasses.replace(reach, operator=toy.operator))
    with pytest.raises(ScenarioError, match="a PointScenario or a TaskScenario, not Scenario"):
        resolve(Scenario())


def test_a_scenario_made_in_python_may_hold_numpy_arrays():
    """A script may set a list field from NumPy (`start`, `goals`): resolved as the lists of
    the same values, not refused by NumPy's "truth value of an array is ambiguous"."""
    scene = load_scenario_file(DIAGRAMS / "toy_alt_vs_cont.yaml").scenario
    arrays = dataclasses.replace(scene, start=np.array(scene.start),
                                 goals=np.array(scene.goals))
    resolved, expected = resolve(arrays), resolve(scene)
    assert resolved.scenario.goals == scene.goals and resolved.scenario.start == scene.start
    assert np.array_equal(resolved.goals, expected.goals)
    assert np.array_equal(resolved.start, expected.start)
