"""The referee of the grasping task: targets, switches, success (a grasp pose within 3 cm
and 10 degrees), metrics; it ends the simulation at success."""

import numpy as np

from pbp_drake.core.grasp_task import grasp_progress, grasp_success
from pbp_drake.core.hand_over import check_limit
from pbp_drake.core.quaternion import unit_quaternions
from pbp_drake.systems.ports import PoseState, finite_pose_state
from pbp_drake.systems.tasks.task_monitor import TaskMonitorBase


class GraspTaskMonitor(TaskMonitorBase):
    """`TaskMonitor`'s rules (`TaskMonitorBase`) with grasp poses
    (`pbp_drake.core.grasp_task`).

    .. pydrake_system::

        name: GraspTaskMonitor
        input_ports:
        - hand_pose
        - operator_active
        output_ports:
        - target
        - task_status

    `hand_pose` is the hand's `PoseState`. Progress is `grasp_progress` toward the current
    target's grasp pose from `start_pose` (`[p (3), q (4)]`, length per radian
    `success_distance / success_angle`); success is the hand within `success_distance` (m)
    AND `success_angle` (rad) of it. `grasp_positions` (M, 3) and `grasp_orientations`
    (M, 4) are the objects' grasp poses; `target` gives the grasp position.
    """

    _objects_name = "grasp_positions"

    def __init__(self, grasp_positions, grasp_orientations, targets, switch_schedule,
                 start_pose, success_distance, success_angle, control_period):
        super().__init__("hand_pose", PoseState.size, grasp_positions, targets,
                         switch_schedule, control_period)
        self._orientations = np.asarray(grasp_orientations, float)
        if self._orientations.shape != (len(self._objects), 4):
            raise ValueError(f"grasp_orientations must be one quaternion (w, x, y, z) per grasp "
                             f"position, ({len(self._objects)}, 4), got shape "
                             f"{self._orientations.shape}")
        unit_quaternions(self._orientations, "grasp_orientations")  # a check: kept as given
        start_pose = np.asarray(start_pose, float)
        if start_pose.shape != (7,) or not np.isfinite(start_pose).all():
            raise ValueError(f"start_pose must be 7 finite numbers [x, y, z, qw, qx, qy, qz], "
                             f"got {start_pose.tolist()}")
        unit_quaternions(start_pose[3:], "start_pose orientation")
        self._start_position, self._start_orientation = start_pose[:3], start_pose[3:7]
        self._success_distance = check_limit(success_distance, "success_distance", "m")
        self._success_angle = check_limit(success_angle, "success_angle", "rad")
        self._length_per_radian = self._success_distance / self._success_angle

    @property
    def grasp_orientations(self):
        return self._orientations

    def _read_hand(self, vector):
        hand = finite_pose_state(vector, "hand_pose")
        return hand[:3], hand[3:7] / np.linalg.norm(hand[3:7])

    def _progress(self, hand, index):
        position, orientation = hand
        return grasp_progress(position, orientation, self._start_position,
                              self._start_orientation, self._objects[index],
                              self._orientations[index], self._length_per_radian)

    def _reached(self, hand, index):
        position, orientation = hand
        return grasp_success(position, orientation, self._objects[index],
                             self._orientations[index], self._success_distance,
                             self._success_angle)
