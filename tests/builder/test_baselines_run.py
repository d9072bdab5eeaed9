"""The shared-autonomy baselines end to end with the virtual participant: HOP and
predict-then-assist reach the target on the reaching task without any DMP; PBP with the
``maxent_command`` estimator picks its DMP from the operator's commands; the posterior's
clip ratio reaches the TaskResult, a streamed run and a study's trial file. A reaching run
takes under a second; the obstacle and grasping tasks' runs are marked slow."""

import dataclasses
import functools

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator

from pbp_drake.builder import build_diagram, find_system, run_task
from pbp_drake.builder.streamed_run import run_task_streamed
from pbp_drake.scenarios import load_scenario_file, resolve, with_method
from pbp_drake.systems import (
    HopAssistance, MaxEntGoalEstimator, PoseHopAssistance, PoseMaxEntGoalEstimator)

# Whole short runs of the reaching task (5 s of the fast suite): `make test` runs them.
pytestmark = pytest.mark.slow

# Tuning seeds: the evaluation seeds are for the results only.
SEED = 3


def scenario(repo, name, method, estimator=None, **hop):
    loaded = load_scenario_file(repo / "diagrams" / name).scenario
    if hop:
        loaded = dataclasses.replace(loaded, hop=dataclasses.replace(loaded.hop, **hop))
    if estimator is not None:
        loaded = dataclasses.replace(loaded, goal_estimator=dataclasses.replace(
            loaded.goal_estimator, method=estimator))
    return resolve(dataclasses.replace(with_method(loaded, method), seed=SEED))


@functools.cache
def teleop_run(repo, name):
    """Teleop's run of scene `name` on SEED, simulated once for the tests that compare with
    it (a run is deterministic)."""
    return run_task(scenario(repo, name, "teleop"))


@pytest.mark.parametrize("method", ["hop", "predict_then_assist"])
def test_the_baselines_reach_the_target_without_dmps(repo, method):
    resolved = scenario(repo, "hsr_reach.yaml", method)
    diagram = build_diagram(resolved)
    assert isinstance(find_system(diagram, "goal_estimator"), MaxEntGoalEstimator)
    assert isinstance(find_system(diagram, "assistance"), HopAssistance)
    with pytest.raises(KeyError):
        find_system(diagram, "dmp_bank")
    result = run_task(resolved, diagram=diagram)
    assert result.success and result.switches == 2
    # The keys are teleop's; the participant presses where the robot does not serve its
    # target and lets it go where it does, so it acts on some ticks, not all.
    assert 0.0 < result.intervention_ratio < 1.0
    # The estimate the trial CSV records ends on the final target.
    assert result.selected_goals[-1] == result.targets[-1]
    assert 0.0 <= result.posterior_clipped_ratio <= 1.0


def test_hop_is_faster_than_teleop_with_the_same_participant(repo):
    """HOP adds its action to the operator's command: the same participant, the same
    scene, less time."""
    hop = run_task(scenario(repo, "hsr_reach.yaml", "hop"))
    teleop = teleop_run(repo, "hsr_reach.yaml")
    assert hop.task_time < teleop.task_time
    assert teleop.posterior_clipped_ratio is None


@pytest.mark.parametrize("method", ["pbp_alternated", "pbp_continuous"])
def test_pbp_with_the_maxent_command_estimator_reaches_the_target(repo, method):
    resolved = scenario(repo, "hsr_reach.yaml", method, estimator="maxent_command")
    diagram = build_diagram(resolved)
    estimator = find_system(diagram, "goal_estimator")
    assert isinstance(estimator, MaxEntGoalEstimator)
    assert (estimator.margin, estimator.hold_steps) == (0.1, 2)  # the section's hysteresis
    result = run_task(resolved, diagram=diagram)
    assert result.success and result.switches == 2
    # PBP still saves the operator's input: it acts only when the DMP heads elsewhere.
    assert result.intervention_ratio < 0.6
    assert result.posterior_clipped_ratio is not None


def test_a_streamed_run_records_the_same_clip_ratio(repo, tmp_path):
    resolved = scenario(repo, "hsr_reach.yaml", "hop")
    whole = run_task(resolved)
    streamed = run_task_streamed(resolved, tmp_path / "run.csv", chunk_seconds=1.0)
    assert streamed.posterior_clipped_ratio == whole.posterior_clipped_ratio
    assert streamed.task_time == whole.task_time


@pytest.mark.slow
@pytest.mark.parametrize("method", ["hop", "predict_then_assist"])
def test_the_baselines_do_the_obstacle_task(repo, method):
    result = run_task(scenario(repo, "hsr_obstacles.yaml", method))
    assert result.success
    # One goal: the posterior is certain from the start and nothing is clipped.
    assert result.posterior_clipped_ratio == 0.0


@pytest.mark.slow
@pytest.mark.parametrize("method, estimator", [("hop", None), ("predict_then_assist", None),
                                               ("pbp_alternated", "maxent_command")])
def test_the_grasp_task_with_hops_posterior(repo, method, estimator):
    resolved = scenario(repo, "hsr_grasp.yaml", method, estimator)
    diagram = build_diagram(resolved)
    assert isinstance(find_system(diagram, "goal_estimator"), PoseMaxEntGoalEstimator)
    if estimator is None:
        assert isinstance(find_system(diagram, "assistance"), PoseHopAssistance)
    result = run_task(resolved, diagram=diagram)
    assert result.success
    assert result.final_angle_to_target <= 10.0
    assert np.isfinite(result.posterior_clipped_ratio)


@pytest.mark.parametrize("name", ["hsr_reach.yaml", "hsr_grasp.yaml"])
def test_the_baselines_draw_their_scene_without_dmp_paths(repo, meshcat, name):
    """With Meshcat the scene is drawn as under PBP, without the DMPs' predicted paths."""
    resolved = scenario(repo, name, "hop")
    diagram = build_diagram(resolved, meshcat)
    assert diagram.HasSubsystemNamed("task_visualizer")
    simulator = Simulator(diagram)
    simulator.AdvanceTo(0.5)
    assert meshcat.HasPath("/task/objects/0") and meshcat.HasPath("/task/target")


@pytest.mark.parametrize("name", ["hsr_reach.yaml", "hsr_grasp.yaml"])
@pytest.mark.parametrize("method", ["hop", "predict_then_assist"])
def test_with_its_assistance_off_a_baseline_commands_what_teleop_commands(repo, name, method):
    """`hop: {assistance: false}`: the robot adds nothing, so the same participant on the
    same seed moves the hand exactly as under teleop, tick for tick (the pose too in the
    grasping task); the posterior still runs."""
    teleop = teleop_run(repo, name)
    off = run_task(scenario(repo, name, method, assistance=False))
    for series in ("ee_positions", "headings", "commands", "operator_active",
                   "operator_commands", "command_angular_velocities", "angles_to_target"):
        np.testing.assert_array_equal(getattr(off, series), getattr(teleop, series),
                                      err_msg=series)
    assert (off.success, off.task_time) == (teleop.success, teleop.task_time)
    assert off.posterior_clipped_ratio is not None
