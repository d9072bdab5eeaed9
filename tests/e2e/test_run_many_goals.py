"""`pbp-drake run --goals K` (`task.grid_objects`): a reaching scene of K candidate goals on a
grid over the task's region, from the seed; refused where it does not apply."""

import dataclasses

import numpy as np
import pytest

from pbp_drake.cli import build_parser
from pbp_drake.commands.run import scenario_for_run
from pbp_drake.core.reach_task import sample_grid_scene
from pbp_drake.scenarios import ScenarioError, load_scenario_file, resolve
from pbp_drake.scenarios.bounds import MAX_GOALS


def run_scenario(path, *flags):
    """The resolved scenario `pbp-drake run PATH FLAGS...` runs."""
    return scenario_for_run(build_parser().parse_args(["run", str(path), *flags]))


def test_goals_places_k_objects_in_the_region_apart_and_the_targets_among_them(repo):
    path = repo / "diagrams" / "hsr_reach.yaml"
    file = load_scenario_file(path)
    resolved = run_scenario(path, "--seed", "3", "--goals", "2000")
    objects = np.asarray(resolved.goals)
    task = file.scenario.task
    assert objects.shape == (2000, 3)
    assert (objects[:, 0] >= task.x_range[0]).all() and (objects[:, 0] <= task.x_range[1]).all()
    assert (objects[:, 1] >= task.y_range[0]).all() and (objects[:, 1] <= task.y_range[1]).all()
    targets = resolved.scene.targets
    assert len(targets) == len(task.switch_schedule)
    assert all(a != b for a, b in zip(targets, targets[1:]))  # each switch to another object
    # The same seed, the same scene.
    again = run_scenario(path, "--seed", "3", "--goals", "2000")
    np.testing.assert_array_equal(again.goals, objects)


def test_the_grid_keeps_objects_half_a_cell_apart():
    scene, separation = sample_grid_scene(0, 500)
    gaps = np.linalg.norm(scene.objects[:, None, :2] - scene.objects[None, :, :2], axis=-1)
    gaps[np.diag_indices(500)] = np.inf
    assert gaps.min() >= separation > 0


@pytest.mark.parametrize("name, goals, message", [
    ("hsr_obstacles.yaml", 10,
     "^--goals places a reaching task's objects; this scenario's task is !DynamicObstacles$"),
    ("hsr_grasp.yaml", 10,
     "^--goals places a reaching task's objects; this scenario's task is !GraspTask$"),
    ("hsr_reach.yaml", 1, "scenario.task.grid_objects 1 is out of range; expected 2 to"),
    ("hsr_reach.yaml", MAX_GOALS + 1, "is out of range"),
    ("hsr_reach.yaml", -5, "scenario.task.grid_objects -5 is out of range")])
def test_goals_is_refused_where_it_does_not_apply(repo, name, goals, message):
    with pytest.raises(ScenarioError, match=message):
        run_scenario(repo / "diagrams" / name, "--goals", str(goals))


def test_a_grid_and_given_objects_are_refused_together(repo):
    scenario = load_scenario_file(repo / "diagrams" / "hsr_reach.yaml").scenario
    scenario = dataclasses.replace(scenario, task=dataclasses.replace(
        scenario.task, grid_objects=10, objects=[[1.5, 0.0, 0.7], [2.0, 0.0, 0.7]],
        targets=[0, 1, 0]))
    with pytest.raises(ScenarioError, match="grid_objects places objects on a grid; "
                       "scenario.task.objects are given"):
        resolve(scenario)


def test_a_task_without_switches_takes_a_single_goal(repo):
    scenario = load_scenario_file(repo / "diagrams" / "hsr_reach.yaml").scenario
    scenario = dataclasses.replace(scenario, task=dataclasses.replace(
        scenario.task, switch_schedule=[0.0], grid_objects=1))
    assert resolve(scenario).goals.shape == (1, 3)


def test_each_seed_draws_its_own_grid(repo):
    """A study's trials (one seed each) each get their jittered grid and targets."""
    path = repo / "diagrams" / "hsr_reach.yaml"
    first, second = (run_scenario(path, "--seed", seed, "--goals", "100") for seed in "12")
    assert not np.array_equal(first.goals, second.goals)
