"""The closed-loop bench's scenes (`pbp_drake_bench.scenes`): K objects on a jittered grid,
the target the first, no switches; the grasp scene's poses drawn by the core's own
functions; both built by the normal builder and run to their target by the virtual
participant."""

import numpy as np
import pytest

from pbp_drake_bench.scenes import GRASP, REACH, grasp_resolved, resolved_scene
from pbp_drake.builder.run import run_task
from pbp_drake.core.grasp_task import grasp_pose


@pytest.mark.slow
@pytest.mark.parametrize("task", [REACH, GRASP])
def test_a_scene_has_k_goals_in_the_task_region_and_targets_the_first(task):
    resolved = resolved_scene(task, 1000)
    task_config = resolved.scenario.task
    goals = resolved.goals
    assert goals.shape == (1000, 3)
    assert resolved.scene.targets == (0,) and resolved.scene.switch_schedule == (0.0,)
    assert list(task_config.switch_schedule) == [0.0]
    objects = resolved.scene.objects if task == REACH else resolved.scene.grasps.tables
    assert objects[:, 0].min() >= task_config.x_range[0]
    assert objects[:, 0].max() <= task_config.x_range[1]
    assert objects[:, 1].min() >= task_config.y_range[0]
    assert objects[:, 1].max() <= task_config.y_range[1]
    gaps = np.linalg.norm(objects[:, None, :2] - objects[None, :, :2], axis=-1)
    gaps[np.diag_indices(len(objects))] = np.inf
    assert gaps.min() > 0.0  # one object a cell


def test_the_grasp_poses_are_the_cores_and_the_dmps_last_to_the_farthest():
    resolved = grasp_resolved(50, seed=3)
    grasps = resolved.scene.grasps
    task = resolved.scenario.task
    assert set(grasps.approaches) == {"side", "top"}
    for index in (0, 17, 49):
        position, orientation = grasp_pose(grasps.objects[index], grasps.approaches[index],
                                           grasps.approach_angles[index], task.object_height,
                                           task.grasp_depth)
        np.testing.assert_allclose(grasps.grasp_positions[index], position)
        np.testing.assert_allclose(grasps.grasp_orientations[index], orientation)
    np.testing.assert_array_equal(resolved.goals, grasps.grasp_positions)
    farthest = np.max(np.linalg.norm(resolved.goals - resolved.start, axis=1))
    assert resolved.controller.dmp_duration == pytest.approx(farthest / resolved.nominal_speed)


@pytest.mark.slow
@pytest.mark.parametrize("task", [REACH, GRASP])
def test_the_virtual_participant_reaches_the_target(task):
    result = run_task(resolved_scene(task, 4))
    assert result.success and result.switches == 0
    assert set(result.targets) == {0}
