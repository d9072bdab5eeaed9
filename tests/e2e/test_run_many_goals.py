"""`pbp-drake run --goals K`: a reaching scene of K candidate goals on a grid over the task's
region, from the seed; refused where it does not apply."""

import dataclasses

import numpy as np
import pytest

from pbp_drake.cli import build_parser
from pbp_drake.commands.run import scenario_for_run, with_grid_goals
from pbp_drake.core.reach_task import sample_grid_scene
from pbp_drake.scenarios import ScenarioError, load_scenario_file
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
    ("hsr_obstacles.yaml", 10, "--goals places the objects of a reaching task"),
    ("hsr_grasp.yaml", 10, "--goals places the objects of a reaching task"),
    ("hsr_reach.yaml", 1, "--goals 1 is out of range; expected 2 to"),
    ("hsr_reach.yaml", MAX_GOALS + 1, "is out of range")])
def test_goals_is_refused_where_it_does_not_apply(repo, name, goals, message):
    with pytest.raises(ScenarioError, match=message):
        run_scenario(repo / "diagrams" / name, "--goals", str(goals))


def test_a_task_without_switches_takes_a_single_goal(repo):
    scenario = load_scenario_file(repo / "diagrams" / "hsr_reach.yaml").scenario
    scenario = dataclasses.replace(scenario, task=dataclasses.replace(
        scenario.task, switch_schedule=[0.0]))
    assert len(with_grid_goals(scenario, 1).task.objects) == 1
