"""The grasping task's scene from its config (`GraspTask`): the schema's degrees turned into
the core's radians, the region checked, the scene drawn from the seed
(`pbp_drake.core.grasp_task`). `resolution.task_scene` makes it a `TaskScene`."""

import numpy as np

from pbp_drake.core.grasp_task import sample_grasp_scene
from pbp_drake.core.reach_task import validate_objects


def grasp_scene(task, seed):
    """The `GraspScene` of `task` (a checked `GraspTask`) drawn from `seed`; ValueError if
    its region is out of reach or its tables cannot be placed."""
    # Every corner of the tables' region must be in the HSR's reach, as in reach.
    validate_objects([[x, y, task.table_height] for x in task.x_range for y in task.y_range],
                     0.0)
    return sample_grasp_scene(
        seed, object_count=tuple(task.object_count), x_range=tuple(task.x_range),
        y_range=tuple(task.y_range), table_height=task.table_height,
        table_size=tuple(task.table_size), object_radius=task.object_radius,
        object_height=task.object_height, min_separation=task.min_separation,
        switch_schedule=tuple(task.switch_schedule),
        yaw_range=tuple(np.radians(task.approach_yaw_range)),
        roll_range=tuple(np.radians(task.roll_range)), top_probability=task.top_probability,
        grasp_depth=task.grasp_depth)
