"""The grasping task's scenario (`task: !GraspTask`): diagrams/hsr_grasp.yaml loads and
resolves, bad fields are refused naming them, and a person at the keyboard or gamepad
drives it from the page (and only from the page)."""

import dataclasses

import numpy as np
import pytest

from pbp_drake import cli
from pbp_drake.builder import build_diagram
from pbp_drake.core.grasp_task import sample_grasp_scene
from pbp_drake.scenarios import (
    Gamepad, GraspTask, Keyboard, ScenarioError, load_scenario_file, resolve)


@pytest.fixture(scope="module")
def shipped(repo):
    return load_scenario_file(repo / "diagrams" / "hsr_grasp.yaml")


def test_the_shipped_file_loads_with_its_defaults(shipped):
    task = shipped.scenario.task
    assert isinstance(task, GraspTask)
    assert task == GraspTask()  # the file spells out the defaults
    assert (task.approach_yaw_range, task.roll_range) == ([-60.0, 60.0], [-90.0, 90.0])
    assert (task.success_distance, task.success_angle) == (0.03, 10.0)
    assert shipped.scenario.goal_estimator.method == "pose"


def test_resolving_draws_the_seeds_scene_with_the_grasp_positions_as_goals(shipped):
    resolved = shipped.resolved
    layout = resolved.scene
    expected = sample_grasp_scene(
        0, yaw_range=(-np.pi / 3, np.pi / 3), roll_range=(-np.pi / 2, np.pi / 2))
    np.testing.assert_allclose(layout.grasps.grasp_orientations,
                               expected.grasp_orientations)
    np.testing.assert_array_equal(layout.objects, layout.grasps.grasp_positions)
    np.testing.assert_array_equal(resolved.goals, layout.grasps.grasp_positions)
    assert layout.targets == expected.targets
    assert layout.switch_schedule == (0.0, 0.3, 0.6)
    # One goal per object's grasp position (the builder fits the DMPs).
    assert len(resolved.goals) == len(layout.objects)
    assert resolved.station.ee_height == 0.7


def test_another_seed_another_scene(shipped):
    other = resolve(dataclasses.replace(shipped.scenario, seed=1))
    assert not np.array_equal(other.scene.objects[:2], shipped.resolved.scene.objects[:2])


@pytest.mark.parametrize("config, system", [(Keyboard, "PoseKeyboardOperator"),
                                             (Gamepad, "PoseGamepadOperator")])
def test_a_person_drives_the_grasp_from_the_page_only(shipped, meshcat, config, system):
    resolved = resolve(dataclasses.replace(shipped.scenario, operator=config()))
    with pytest.raises(ValueError, match=f"operator !{config.__name__} reads the browser: "
                                         "it needs Meshcat"):
        build_diagram(resolved)
    diagram = build_diagram(resolved, meshcat)
    assert type(diagram.GetSubsystemByName("operator")).__name__ == system
    assert diagram.HasSubsystemNamed("task_visualizer")


def with_task(shipped, **fields):
    scenario = shipped.scenario
    return dataclasses.replace(scenario, task=dataclasses.replace(scenario.task, **fields))


@pytest.mark.parametrize("fields, message", [
    (dict(approach_yaw_range=[-100.0, 60.0]),
     r"scenario.task.approach_yaw_range \[-100.0, 60.0\] leaves \[-90.0, 90.0\]"),
    (dict(approach_yaw_range=[30.0, -30.0]), r"scenario.task.approach_yaw_range .* reversed"),
    (dict(roll_range=[-90.0, 200.0]), r"scenario.task.roll_range .* leaves \[-180.0, 180.0\]"),
    (dict(success_distance=0.0), "scenario.task.success_distance must be finite and positive"),
    (dict(success_distance=-0.03),
     "scenario.task.success_distance must be finite and positive"),
    (dict(success_angle=0.0), "scenario.task.success_angle must be finite and positive"),
    (dict(success_angle=180.0), "scenario.task.success_angle 180.0 degrees admits every"),
    (dict(grasp_depth=-0.1), "scenario.task.grasp_depth must be finite and not negative"),
    (dict(top_probability=1.5), "scenario.task.top_probability 1.5 is no probability"),
    (dict(table_size=[0.3]), r"scenario.task.table_size \[0.3\] needs two positive lengths"),
    (dict(table_size=[0.3, -0.3]), r"scenario.task.table_size .* needs two positive"),
    (dict(object_count=[0, 3]), r"scenario.task.object_count\[0\] 0 is out of range"),
    (dict(switch_schedule=[0.2, 0.6]), "scenario.task.switch_schedule .* must start at 0.0"),
    (dict(min_separation=0.3), "scenario.task: min_separation 0.3 m is less than the "
                               "tables' diagonal"),
    (dict(x_range=[4.0, 5.0]), "scenario.task: object .* is out of reach"),
    (dict(table_height=1.0, top_probability=1.0), "scenario.task: object 0's grasp puts "
                                                  "the hand at height"),
])
def test_bad_fields_are_refused_naming_them(shipped, fields, message):
    with pytest.raises(ScenarioError, match=message):
        resolve(with_task(shipped, **fields))


def test_a_success_region_holding_the_start_is_refused(shipped):
    # One table right where the hand starts, grasped from the side at yaw 0.
    start = shipped.resolved.start
    scenario = with_task(shipped, object_count=[1, 1], switch_schedule=[0.0],
                         x_range=[start[0] + 0.08, start[0] + 0.08],
                         y_range=[start[1], start[1]], table_height=start[2] - 0.075,
                         top_probability=0.0, approach_yaw_range=[0.0, 0.0],
                         success_distance=0.05)
    with pytest.raises(ScenarioError, match="scenario.task.success_distance 0.05 m reaches "
                                            "the nearest object"):
        resolve(scenario)


def test_the_pose_estimator_needs_the_grasping_task(repo):
    reach = load_scenario_file(repo / "diagrams" / "hsr_reach.yaml").scenario
    scenario = dataclasses.replace(reach, goal_estimator=dataclasses.replace(
        reach.goal_estimator, method="pose"))
    with pytest.raises(ScenarioError, match="scenario.goal_estimator.method pose reads grasp "
                                            "orientations: use it with task: !GraspTask"):
        resolve(scenario)


@pytest.mark.parametrize("estimator", ["angle", "nearest", "bayesian"])
def test_a_position_estimator_is_refused_by_the_grasping_task(repo, capsys, estimator):
    arguments = ["run", str(repo / "diagrams" / "hsr_grasp.yaml"), "--no-meshcat",
                 "--set", f"goal_estimator.method={estimator}"]
    assert cli.main(arguments) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1
    assert error.endswith(f"scenario.goal_estimator.method {estimator} reads positions alone; "
                          "the grasping task takes one that reads grasp poses: pose, "
                          "maxent_command, intent_filter\n")


def test_a_yaml_typo_in_the_task_names_the_key(shipped, tmp_path):
    text = shipped.path.read_text().replace("roll_range:", "rol_range:")
    path = tmp_path / "grasp.yaml"
    path.write_text(text)
    with pytest.raises(ScenarioError, match=r"unknown key 'rol_range' \(did you mean "
                                            r"'roll_range'\?\)"):
        load_scenario_file(path)


@pytest.mark.parametrize("operator, controls", [
    ("keyboard", "Keys: arrows move the hand (not forward: the primitive drives it), "
                 "PageUp/PageDown"),
    ("gamepad", "Gamepad: left stick moves the hand (not forward: the primitive drives it), "
                "triggers")])
def test_run_waits_for_a_browser_and_refuses_when_none_joins(repo, capsys, operator,
                                                             controls):
    arguments = ["run", str(repo / "diagrams" / "hsr_grasp.yaml"), "--operator", operator,
                 "--wait-for-browser", "0", "--port", "0"]
    assert cli.main(arguments) == 2
    captured = capsys.readouterr()
    assert "(waiting up to 0 s); the task starts when Start is pressed" in captured.out
    assert controls in captured.out
    assert captured.err.startswith("pbp-drake: no browser opened http://")
    assert "nothing was run or recorded" in captured.err
