"""`robot: !Arm {...}` in a scenario file: the shipped arm_reach.yaml resolves to a scene in
the arm's region, a user's own model is a change of its names, and what cannot work is
refused in one line naming the scenario's field."""

import dataclasses
import pathlib

import numpy as np
import pytest

from pbp_drake.builder import build_diagram, run_task
from pbp_drake.scenarios import DynamicObstacles, ScenarioError, load_scenario_file, resolve

REPO = pathlib.Path(__file__).resolve().parents[2]
ARM_REACH = REPO / "diagrams" / "arm_reach.yaml"
ARM6 = REPO / "tests" / "robots" / "models" / "pbp_arm6_other.urdf"


def arm_scenario(**robot_changes):
    scenario = load_scenario_file(ARM_REACH).scenario
    return dataclasses.replace(scenario,
                               robot=dataclasses.replace(scenario.robot, **robot_changes))


def other_arm():
    """The 6-joint test arm in place of ours: model_file, frames and ready configuration."""
    ready = ARM6.read_text().split("ready configuration: [")[1].split("]")[0]
    return dict(model_file=str(ARM6), base_frame="arm6_base", ee_frame="arm6_tool",
                initial_positions=[float(v) for v in ready.split(",")])


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_scene_is_drawn_in_the_arms_region(seed):
    resolved = resolve(dataclasses.replace(arm_scenario(), seed=seed))
    goals, task = resolved.goals, resolved.scenario.task
    assert 2 <= len(goals) <= 4
    for axis, (low, high) in enumerate([task.x_range, task.y_range, task.z_range]):
        assert (goals[:, axis] >= low).all() and (goals[:, axis] <= high).all()
    assert len(set(np.round(goals[:, 2], 6))) == len(goals)  # each at a height of its own
    assert resolved.station.control_period == resolved.scenario.control_period
    hand_over = resolved.controller.hand_over
    assert hand_over.max_heading_turn == resolved.scenario.robot.max_heading_turn


def test_the_diagram_has_the_arm_station_and_the_same_controller():
    diagram = build_diagram(resolve(arm_scenario()))
    assert diagram.HasSubsystemNamed("arm_station")
    assert diagram.HasSubsystemNamed("pbp_controller")
    assert not diagram.HasSubsystemNamed("hsr_station")


@pytest.mark.parametrize("changes, message", [
    ({"model_file": "models/no_such_arm.urdf"},
     "scenario.robot.model_file: no file at 'models/no_such_arm.urdf'"),
    ({"ee_frame": "tool0"}, "scenario.robot.ee_frame 'tool0' is not a frame of"),
    ({"ee_frame": "arm7_base"}, "scenario.robot.ee_frame 'arm7_base' is not on the arm"),
    ({"max_heading_turn": 0.0}, "scenario.robot.max_heading_turn must be finite and positive"),
])
def test_a_robot_that_cannot_work_names_the_field(changes, message):
    with pytest.raises(ScenarioError) as error:
        resolve(arm_scenario(**changes))
    assert message in str(error.value) and "\n" not in str(error.value)


def test_a_goal_region_out_of_reach_is_refused_with_the_reach_the_arm_has():
    scenario = arm_scenario()
    far = dataclasses.replace(scenario.task, x_range=[0.4, 1.6])
    with pytest.raises(ScenarioError, match=r"scenario\.task: \(1\.60, .*\) m is .* m from "
                       r"the arm's shoulder at .*, beyond its reach of \d\.\d\d m"):
        resolve(dataclasses.replace(scenario, task=far))


@pytest.mark.parametrize("change", [dict(z_range=[0.0, 0.0]),
                                    dict(objects=[[0.5, 0.0, 0.04], [0.5, 0.2, 0.3]],
                                         targets=[0, 1, 0])])
def test_an_object_too_low_for_its_table_is_refused(change):
    # Was Drake's Box() failure (a table of negative height) when the scene was drawn.
    scenario = arm_scenario()
    low = dataclasses.replace(scenario.task, **change)
    with pytest.raises(ScenarioError, match=r"scenario\.task: \(0\.\d\d, .*\) m is too low: "
                       r"each object stands on a table, its centre at least 0\.05 m above"):
        resolve(dataclasses.replace(scenario, task=low))


def test_the_grasping_task_is_refused_on_an_arm():
    scenario = load_scenario_file(REPO / "diagrams" / "hsr_grasp.yaml").scenario
    with pytest.raises(ScenarioError, match="runs on the HSR's pose station"):
        resolve(dataclasses.replace(scenario, robot=arm_scenario().robot))


def arm_obstacle_scenario():
    """The obstacle task in the arm's workspace: thin cylinders, closer together."""
    scenario = arm_scenario()
    task = DynamicObstacles(x_range=[0.5, 0.7], y_range=[-0.25, 0.25], height=0.35,
                            success_distance=0.03, obstacle_count=2, obstacle_radius=0.03,
                            obstacle_height=0.6, obstacle_speed=0.04,
                            obstacle_x_range=[0.3, 0.7], obstacle_y_range=[-0.4, 0.4],
                            obstacle_spacing=0.15)
    return dataclasses.replace(scenario, name="arm_obstacles", task=task)


def test_the_obstacle_task_takes_an_arm_and_measures_its_collisions():
    resolved = resolve(arm_obstacle_scenario())
    assert len(resolved.station.obstacles) == 2
    diagram = build_diagram(resolved)
    assert diagram.GetSubsystemByName("arm_station").HasOutputPort("in_collision")


def test_the_hsr_obstacle_scene_is_out_of_the_arms_reach():
    scenario = load_scenario_file(REPO / "diagrams" / "hsr_obstacles.yaml").scenario
    with pytest.raises(ScenarioError, match="beyond its reach of"):
        resolve(dataclasses.replace(scenario, robot=arm_scenario().robot))


@pytest.mark.slow
@pytest.mark.parametrize("method", ["pbp_alternated", "teleop"])
def test_the_obstacle_task_runs_on_the_arm(method):
    result = run_task(dataclasses.replace(arm_obstacle_scenario(), method=method, seed=0))
    assert result.success and result.in_collision is not None


@pytest.mark.slow
@pytest.mark.parametrize("method", ["pbp_alternated", "pbp_continuous", "teleop", "hop"])
@pytest.mark.parametrize("arm", ["arm7", "arm6"])
def test_the_task_runs_on_either_arm_unchanged(arm, method):
    changes = other_arm() if arm == "arm6" else {}
    scenario = dataclasses.replace(arm_scenario(**changes), method=method, seed=10_000)
    result = run_task(scenario)
    assert result.success, (arm, method, result)
