"""The closed-loop bench's scenes: the HSR reaching task and the grasping (six-DoF pose) task
with K goals, each K objects on a jittered grid in the task's region, the target the first
of them, no switches. Both are resolved scenarios (`pbp_drake.scenarios.ResolvedScenario`)
that `pbp_drake.builder.build_diagram` builds as it builds the shipped files.

The reaching task's objects go through the normal resolution (`resolve`). The grasping
task's cannot: its tables must stand `min_separation` (their diagonal) apart, and 1,000 of
them do not fit in its region. So the grasp scene resolves the shipped file as it is and
replaces its `TaskScene` with one built here: the same grid, each object on its table with
a grasp pose drawn from a seeded generator by the core's own functions (`grasp_pose`: side
at a yaw, top at a wrist roll, in the file's ranges). The tables then overlap: the bench
measures how the loop scales with K, not a task a person could do."""

import dataclasses
import functools
from pathlib import Path

import numpy as np

from pbp_drake.core.grasp_task import GraspScene, grasp_pose
from pbp_drake.core.reach_task import jittered_grid
from pbp_drake.scenarios import load_scenario_file, resolve
from pbp_drake.scenarios.resolution import TaskScene

REACH, GRASP = "reach", "grasp"
TASKS = (REACH, GRASP)
# The repository's diagrams/ folder (this file is pbp_drake_bench/scenes.py).
DIAGRAMS = Path(__file__).resolve().parents[1] / "diagrams"
SCENARIO_FILES = {REACH: DIAGRAMS / "hsr_reach.yaml", GRASP: DIAGRAMS / "hsr_grasp.yaml"}


def hsr_scenario(goal_count, seed=0):
    """The HSR reaching scenario of `diagrams/hsr_reach.yaml` with `goal_count` objects on a
    jittered grid in the paper's region, the target the first of them, no switches."""
    scenario = load_scenario_file(SCENARIO_FILES[REACH]).scenario
    task = scenario.task
    floor, (dx, dy) = jittered_grid(goal_count, task.x_range, task.y_range,
                                    np.random.default_rng(seed))
    objects = np.column_stack([floor, np.full(goal_count, task.height)])
    task = dataclasses.replace(task, objects=objects.tolist(), targets=[0],
                               switch_schedule=[0.0],
                               min_separation=min(task.min_separation, 0.4 * min(dx, dy)))
    return dataclasses.replace(scenario, task=task)


def grasp_scene_grid(task, goal_count, rng):
    """A `GraspScene` of `goal_count` objects on a jittered grid in `task`'s region (a
    `GraspTask`), each standing on its table, grasped from above with the task's
    `top_probability` at a wrist roll in its `roll_range`, else from the side at a yaw in its
    `approach_yaw_range`; the target the first object."""
    floor, _ = jittered_grid(goal_count, task.x_range, task.y_range, rng)
    tables = np.column_stack([floor, np.full(goal_count, task.table_height)])
    objects = tables + [0.0, 0.0, 0.5 * task.object_height]
    top = rng.uniform(size=goal_count) < task.top_probability
    angles = np.where(top, rng.uniform(*np.radians(task.roll_range), goal_count),
                      rng.uniform(*np.radians(task.approach_yaw_range), goal_count))
    approaches = tuple("top" if is_top else "side" for is_top in top)
    poses = [grasp_pose(center, approach, angle, task.object_height, task.grasp_depth)
             for center, approach, angle in zip(objects, approaches, angles)]
    return GraspScene(objects=objects, tables=tables, approaches=approaches,
                      approach_angles=angles,
                      grasp_positions=np.array([position for position, _ in poses]),
                      grasp_orientations=np.array([orientation for _, orientation in poses]),
                      targets=(0,))


def grasp_resolved(goal_count, seed=0):
    """The grasping scenario of `diagrams/hsr_grasp.yaml` with `goal_count` grasp targets
    (`grasp_scene_grid`), resolved: the file's scenario with no switches resolved as the
    commands resolve it, its scene replaced (and the goals, and the controller's DMP
    duration, which the farthest goal sets)."""
    scenario = load_scenario_file(SCENARIO_FILES[GRASP]).scenario
    scenario = dataclasses.replace(
        scenario, seed=seed, task=dataclasses.replace(scenario.task, switch_schedule=[0.0]))
    resolved = resolve(scenario)
    grasps = grasp_scene_grid(scenario.task, goal_count, np.random.default_rng(seed))
    goals = grasps.grasp_positions
    controller = resolved.controller
    if scenario.dmp_duration <= 0:
        distance = float(np.max(np.linalg.norm(goals - resolved.start, axis=1)))
        controller = dataclasses.replace(controller,
                                         dmp_duration=distance / resolved.nominal_speed)
    scene = TaskScene(objects=goals, targets=grasps.targets, switch_schedule=(0.0,),
                      grasps=grasps)
    return dataclasses.replace(resolved, goals=goals, scene=scene, controller=controller)


def with_motion(scenario, motion):
    """`scenario` with its HSR station's `motion` ("dynamic" or "kinematic")."""
    robot = scenario.robot
    station = dataclasses.replace(robot.station, motion=motion)
    return dataclasses.replace(scenario, robot=dataclasses.replace(robot, station=station))


@functools.lru_cache(maxsize=16)
def resolved_scene(task, goal_count, motion=None, seed=0):
    """The resolved scenario of `task` (REACH or GRASP) with `goal_count` goals, on the
    scenario file's robot or with `motion` (reach only) the station's other motion model;
    resolved once per process (resolving checks the reach objects' separation in O(K^2)
    memory: seconds at K = 10,000), then built afresh for every run. Read-only."""
    if task == REACH:
        scenario = hsr_scenario(goal_count, seed)
        return resolve(scenario if motion is None else with_motion(scenario, motion))
    if task == GRASP and motion is None:
        return grasp_resolved(goal_count, seed)
    raise ValueError(f"task {task!r} with motion {motion!r}: use one of {TASKS}, motion "
                     "with reach only")
