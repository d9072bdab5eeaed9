"""The scene a task puts in front of the robot (`TaskScene`): its goals, targets and
obstacles, given or drawn from the seed (`pbp_drake.core.reach_task`, `obstacle_task`,
`grasp_task`), and checked to be within the robot's reach.
"""

import dataclasses
import typing

import numpy as np

from pbp_drake.core.grasp_task import sample_grasp_scene
from pbp_drake.core.obstacle_task import sample_obstacle_scene
from pbp_drake.core.reach_task import (
    ReachScene, sample_grid_scene, sample_reach_scene, validate_objects)
from pbp_drake.scenarios.schema import DynamicObstacles, GraspTask, MultiGoalReach
from pbp_drake.systems.visualizers.reach_scene_visualizer import OBJECT_HEIGHT


@dataclasses.dataclass(frozen=True)
class TaskScene:
    """What an HSR task puts in front of the robot: the goals `(K, 3)` (one DMP each; the
    grasp positions in the grasping task), the target sequence and its switch schedule, the
    obstacles (None without) and the grasping task's `GraspScene` (None in the others)."""

    objects: np.ndarray
    targets: tuple
    switch_schedule: tuple
    obstacles: typing.Any = None
    grasps: typing.Any = None


def task_scene(task, seed, reach=None):
    """The goals, targets and obstacles of a task, drawn from `seed` when asked. `reach`
    (an arm's `(shoulder, radius)`) replaces the HSR's reach in the checks of where the
    goals may be."""
    if isinstance(task, DynamicObstacles):
        _check_region(task, reach)
        obstacles = sample_obstacle_scene(
            seed, tuple(task.x_range), tuple(task.y_range), task.height,
            task.obstacle_count, tuple(task.obstacle_x_range), tuple(task.obstacle_y_range),
            tuple(task.activation_range), clearance=task.obstacle_spacing,
            fixed_starts=task.obstacle_starts or None)
        return TaskScene(objects=obstacles.target[np.newaxis, :], targets=(0,),
                          switch_schedule=(0.0,), obstacles=obstacles)
    if isinstance(task, GraspTask):
        grasps = _grasp_scene(task, seed)
        return TaskScene(objects=grasps.grasp_positions, targets=grasps.targets,
                          switch_schedule=tuple(task.switch_schedule), grasps=grasps)
    scene = _reach_scene(task, seed, reach)
    return TaskScene(objects=scene.objects, targets=scene.targets,
                      switch_schedule=tuple(task.switch_schedule))


def _reach_scene(task, seed, reach):
    """The objects and target sequence of a reaching task: given, or drawn from the seed."""
    if task.objects:
        objects = _validate_within_reach(task.objects, task.min_separation, reach)
        targets = tuple(int(t) for t in task.targets)
        if len(task.switch_schedule) > 1 and len(objects) < 2:
            raise ValueError("target switching needs at least 2 objects: add objects or set "
                             "switch_schedule to [0.0]")
        if len(targets) != len(task.switch_schedule):
            raise ValueError(f"targets {list(targets)} needs one object index per entry of "
                             f"switch_schedule {task.switch_schedule}")
        if any(not 0 <= t < len(objects) for t in targets):
            raise ValueError(f"targets {list(targets)} name objects that do not exist "
                             f"({len(objects)} objects)")
        if any(a == b for a, b in zip(targets, targets[1:])):
            raise ValueError(f"targets {list(targets)}: each switch must go to a different "
                             "object")
        return ReachScene(objects=objects, targets=targets)
    if task.targets:
        raise ValueError("targets are given without objects")
    _check_region(task, reach)
    if task.grid_objects:
        scene, _ = sample_grid_scene(seed, task.grid_objects, task.x_range, task.y_range,
                                     task.height, task.switch_schedule, task.z_range or None)
        return scene
    return sample_reach_scene(seed, tuple(task.object_count), tuple(task.x_range),
                              tuple(task.y_range), task.height, tuple(task.switch_schedule),
                              task.min_separation, tuple(getattr(task, "z_range", ())))


def _check_region(task, reach, heights=None):
    """Every corner of the region the task draws its targets from (at `heights`, the
    grasping task's table tops; default its `z_range` or `height`) must be in reach."""
    if len(task.x_range) != 2 or len(task.y_range) != 2:
        raise ValueError("x_range and y_range must be [low, high]")
    on_tables = heights is None
    heights = heights or getattr(task, "z_range", None) or [task.height]
    _validate_within_reach([[x, y, z] for x in task.x_range for y in task.y_range
                            for z in heights], 0.0, reach, on_tables)


def _validate_within_reach(objects, min_separation, reach, on_tables=True):
    """`validate_objects` with the HSR's reach, or with an arm's `(shoulder, radius)`: each
    point within radius of the shoulder, refused with the reach the arm has; `on_tables`:
    each point an object's centre, standing on a table of its own."""
    if reach is None:
        objects = validate_objects(objects, min_separation)
    else:
        objects = validate_objects(objects, min_separation, reach_x=(0.0, np.inf),
                                   reach_height=(-np.inf, np.inf))
        shoulder, radius = reach
        distances = np.linalg.norm(objects - shoulder, axis=1)
        farthest = int(np.argmax(distances))
        if distances[farthest] > radius:
            point = ", ".join(f"{value:.2f}" for value in objects[farthest])
            raise ValueError(f"({point}) m is {distances[farthest]:.2f} m from the arm's "
                             f"shoulder at ({', '.join(f'{v:.2f}' for v in shoulder)}), "
                             f"beyond its reach of {radius:.2f} m")
    lowest = int(np.argmin(objects[:, 2]))
    if on_tables and objects[lowest, 2] < OBJECT_HEIGHT / 2:  # a table below the floor
        point = ", ".join(f"{value:.2f}" for value in objects[lowest])
        raise ValueError(f"({point}) m is too low: each object stands on a table, its centre "
                         f"at least {OBJECT_HEIGHT / 2:g} m above the floor")
    return objects


def _grasp_scene(task, seed):
    """The `GraspScene` of `task` (a checked `GraspTask`) drawn from `seed`; ValueError if
    its region is out of reach or its tables cannot be placed."""
    _check_region(task, None, [task.table_height])
    return sample_grasp_scene(
        seed, object_count=tuple(task.object_count), x_range=tuple(task.x_range),
        y_range=tuple(task.y_range), table_height=task.table_height,
        table_size=tuple(task.table_size), object_radius=task.object_radius,
        object_height=task.object_height, min_separation=task.min_separation,
        switch_schedule=tuple(task.switch_schedule),
        yaw_range=tuple(np.radians(task.approach_yaw_range)),
        roll_range=tuple(np.radians(task.roll_range)), top_probability=task.top_probability,
        grasp_depth=task.grasp_depth, grasps_per_object=task.grasps_per_object)


def scene_boxes(task, scene, seed):
    """`(what, lower, upper)` of what the task places: given objects as points, the
    region objects are drawn from, and the obstacles drawn from `seed` (cylinders on the
    floor) as their boxes."""
    if isinstance(task, MultiGoalReach) and task.objects:
        return [(f"scenario.task.objects[{index}] ({', '.join(f'{v:.2f}' for v in point)}) m",
                 point, point) for index, point in enumerate(scene.objects)]
    heights = getattr(task, "z_range", None) or [task.height, task.height]
    names = "z_range" if getattr(task, "z_range", None) else "height"
    boxes = [(f"scenario.task.x_range, y_range and {names} (where the objects are drawn)",
              [task.x_range[0], task.y_range[0], heights[0]],
              [task.x_range[1], task.y_range[1], heights[1]])]
    for index, (x, y) in enumerate(getattr(scene.obstacles, "obstacle_starts", [])):
        radius = task.obstacle_radius
        boxes.append((f"scenario.task's obstacle {index} (drawn with seed {seed} at ({x:.2f}, "
                      f"{y:.2f}) m, obstacle_radius {radius:g} m)", [x - radius, y - radius, 0.0],
                      [x + radius, y + radius, task.obstacle_height]))
    return boxes
