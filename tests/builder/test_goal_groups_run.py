"""Goal groups in whole reaching tasks of a hundred goals on a grid, with the `angle` and the
`intent_filter` estimators: the robot heads into the group the participant points at and
commits only once the goals act as one or the hand is at the group's point, so the
participant lets it go where, following one goal at a time, it corrects the robot most of
the run; the hand-over limits hold through every change of the followed point."""

import dataclasses
import pathlib

import numpy as np
import pytest

from pbp_drake.builder.run import run_task
from pbp_drake.scenarios import load_scenario_file, resolve

pytestmark = pytest.mark.slow  # eight reaching trials of about 2 s each

REACH = pathlib.Path(__file__).resolve().parents[2] / "diagrams" / "hsr_reach.yaml"


def grid_scene(seed, group_mass, method="angle"):
    scenario = load_scenario_file(REACH).scenario
    return resolve(dataclasses.replace(
        scenario, seed=seed, task=dataclasses.replace(scenario.task, grid_objects=100),
        goal_estimator=dataclasses.replace(scenario.goal_estimator, group_mass=group_mass,
                                           method=method)))


@pytest.mark.parametrize("method", ["angle", "intent_filter"])
@pytest.mark.parametrize("seed", [3, 4])
def test_a_hundred_goals_need_less_input_in_groups_than_one_at_a_time(seed, method):
    one_at_a_time = run_task(grid_scene(seed, 0.0))
    grouped_scene = grid_scene(seed, 0.9, method)
    grouped = run_task(grouped_scene)
    assert grouped.success
    assert grouped.intervention_ratio < 0.5 * one_at_a_time.intervention_ratio
    # It shows no goal while uncommitted, and the goal it commits to otherwise (with the
    # intent filter the hand may reach the target before it commits).
    shown = grouped.selected_goals
    assert (shown == -1).any() and ((shown >= -1) & (shown < 100)).all()
    assert method == "intent_filter" or (shown >= 0).any()
    # The hand-over law bounds the command, however the followed point jumps.
    hand_over = grouped_scene.controller.hand_over
    speeds = np.linalg.norm(grouped.commands[:, 3:6], axis=1)
    assert speeds.max() <= hand_over.max_hand_speed + 1e-9
    assert grouped.peak_command_acceleration <= hand_over.max_hand_acceleration + 1e-9
