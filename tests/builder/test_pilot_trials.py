"""Whole trials with each surrogate pilot: under teleop each one takes the hand to the
target on the reaching task, and each runs in the obstacle, grasping and arm tasks (a few
seconds each, their time limit cut)."""

import dataclasses

import numpy as np
import pytest

from pbp_drake.builder.run import run_task
from pbp_drake.scenarios import PILOT_NAMES, load_scenario_file, with_pilot

pytestmark = pytest.mark.slow

SEED = 10_001


@pytest.mark.parametrize("pilot", PILOT_NAMES)
def test_each_pilot_reaches_the_target_under_teleop(repo, pilot):
    scenario = load_scenario_file(repo / "diagrams" / "hsr_reach.yaml").scenario
    result = run_task(dataclasses.replace(with_pilot(scenario, pilot), method="teleop",
                                          seed=SEED))
    assert result.success
    assert 0.5 < result.intervention_ratio <= 1.0


@pytest.mark.parametrize("task", ["hsr_obstacles.yaml", "hsr_grasp.yaml", "arm_reach.yaml"])
@pytest.mark.parametrize("pilot", PILOT_NAMES[1:])
def test_each_pilot_runs_in_every_task(repo, task, pilot):
    scenario = load_scenario_file(repo / "diagrams" / task).scenario
    result = run_task(dataclasses.replace(with_pilot(scenario, pilot),
                                          method="pbp_continuous", seed=SEED, duration=3.0))
    assert result.success or result.task_time == pytest.approx(3.0)
    if pilot in ("noisy", "proportional"):
        # Random keys on 30 % of the ticks; HOP's user presses everywhere off the target.
        assert result.intervention_ratio > 0.2
    assert np.all(np.isfinite(result.ee_positions))
    assert np.all(np.isfinite(result.operator_commands))
