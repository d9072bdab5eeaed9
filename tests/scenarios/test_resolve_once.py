"""Data goes through once: building a shipped scenario computes its demonstration once,
fits its DMPs once and draws its scene once."""

import collections
import pathlib

import pytest

import pbp_drake.core.dmp.bank as dmp_bank_module
import pbp_drake.core.dmp.single as single_dmp_module
import pbp_drake.scenarios.resolution as resolve_module
import pbp_drake.scenarios.task_scenes as task_scenes_module
from pbp_drake.builder import build_diagram
from pbp_drake.scenarios import BentPath, GraspTask, TaskScenario, load_scenario_file, resolve
from pbp_drake.studies.runners import compute_trial

SHIPPED = sorted(pathlib.Path(__file__).resolve().parents[2].glob("diagrams/*.yaml"))
# Where each piece of work is done, by the name the caller looks it up under.
COUNTED = [(resolve_module, "bent_path"), (dmp_bank_module, "fit_weights"),
           (single_dmp_module, "fit_weights"),
           (task_scenes_module, "sample_reach_scene"),
           (task_scenes_module, "sample_obstacle_scene"),
           (task_scenes_module, "sample_grasp_scene")]


@pytest.fixture
def work(monkeypatch):
    """Counts the calls of each piece of work in COUNTED."""
    counts = collections.Counter()
    for module, name in COUNTED:
        original = getattr(module, name)

        def counting(*args, _name=name, _original=original, **kwargs):
            counts[_name] += 1
            return _original(*args, **kwargs)

        monkeypatch.setattr(module, name, counting)
    return counts


def test_every_shipped_scenario_is_counted():
    assert {path.stem for path in SHIPPED} >= {"toy_alpha_study", "toy_alt_vs_cont",
                                               "hsr_reach", "hsr_obstacles"}


@pytest.mark.parametrize("path", SHIPPED, ids=lambda path: path.stem)
def test_loading_and_building_with_meshcat_resolves_once(path, work, meshcat):
    loaded = load_scenario_file(path)
    build_diagram(loaded.resolved, meshcat)
    scenario = loaded.scenario
    task = isinstance(scenario, TaskScenario)
    assert work["bent_path"] == (
        1 if not task and isinstance(scenario.demonstration, BentPath) else 0)
    # Once per bank, where the DMPs run: the 2-D scenes' when resolved, the tasks' in their
    # controller (the grasping task's position and orientation banks from the pose
    # station's hand, both straight); never for a task's straight Pastor DMPs, whose
    # forcing term is 0.
    straight_pastor = task and scenario.dmp.formulation == "pastor"
    banks = 2 if task and isinstance(scenario.task, GraspTask) else 1
    assert work["fit_weights"] == (0 if straight_pastor else banks)
    scenes = (work["sample_reach_scene"] + work["sample_obstacle_scene"]
              + work["sample_grasp_scene"])
    assert scenes == (1 if task else 0)


def test_loading_the_grasping_task_draws_its_scene_once(work):
    load_scenario_file(SHIPPED[0].parent / "hsr_grasp.yaml")
    assert work["sample_grasp_scene"] == 1 and work["fit_weights"] == 0
    assert work["sample_reach_scene"] + work["sample_obstacle_scene"] == 0


def build_then_stop(resolved):
    """A trial's run that builds the task's diagram as `run_task` does, then stops."""
    build_diagram(resolved)
    raise RuntimeError("built")


@pytest.mark.parametrize("name", ["hsr_reach", "hsr_obstacles"])
def test_one_study_trial_resolves_once(name, work):
    loaded = load_scenario_file(SHIPPED[0].parent / f"{name}.yaml")
    work.clear()
    record, _ = compute_trial(loaded.scenario, "pbp_alternated", 0, 7, "digest",
                              run=build_then_stop)
    assert record["error"] == "RuntimeError: built"
    assert record["objects"]  # the scene the trial ran is recorded from the same draw
    assert work["fit_weights"] == 1
    assert work["sample_reach_scene"] + work["sample_obstacle_scene"] == 1


def test_a_scenario_changed_after_resolving_leaves_its_resolution_whole(repo):
    """`resolve` keeps its own copy: a goal or the duration changed in place afterwards
    (on the loaded file's `scenario`, or the one given to `resolve`) neither reaches the
    resolved run's configs nor leaves them disagreeing with the goals derived from them."""
    loaded = load_scenario_file(repo / "diagrams" / "toy_alt_vs_cont.yaml")
    goals, duration = [list(goal) for goal in loaded.scenario.goals], loaded.scenario.duration
    loaded.scenario.goals[0][0] += 0.5
    loaded.scenario.duration = -1.0
    assert loaded.resolved.scenario.goals == goals == loaded.resolved.goals.tolist()
    assert loaded.resolved.scenario.duration == duration
    scenario = load_scenario_file(repo / "diagrams" / "hsr_reach.yaml").scenario
    resolved = resolve(scenario)
    scenario.task.switch_schedule.append(0.9)
    scenario.robot.station.obstacles.append("not an obstacle")
    assert resolved.scenario.task.switch_schedule == [0.0, 0.3, 0.6]
    assert resolved.scenario.robot.station.obstacles == []
