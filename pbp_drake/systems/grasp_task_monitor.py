"""The referee of the grasping task: targets, switches, success (a grasp pose within 3 cm
and 10 degrees), metrics; it ends the simulation at success."""

import numpy as np
from pydrake.systems.framework import EventStatus, LeafSystem

from pbp_drake.core.grasp_task import grasp_progress, grasp_success
from pbp_drake.systems.layouts import PoseState, Target, TaskStatus
from pbp_drake.systems.task_monitor import SUCCESS_MESSAGE, TaskCounts
from pbp_drake.systems.tick import decide_offset, report_offset

_COUNTS_SIZE, _STAGE, _SUCCESS = 5, 0, 4  # TaskCounts as a vector (see task_monitor)


class GraspTaskMonitor(LeafSystem):
    """`TaskMonitor`'s rules with grasp poses (`pbp_drake.core.grasp_task`).

    .. pydrake_system::

        name: GraspTaskMonitor
        input_ports:
        - hand_pose
        - operator_active
        output_ports:
        - target
        - task_status

    `hand_pose` is the hand's `PoseState`. At the decide stage of every tick until success:
    count the tick (and whether the operator acted), compute `grasp_progress` toward the
    current target's grasp pose from the hand's start pose (length per radian
    `success_distance / success_angle`), switch to the next of `targets` once progress
    reaches the next entry of `switch_schedule`, and declare success when the hand is
    within `success_distance` (m) AND `success_angle` (rad) of the target's grasp pose. At
    success it ends the simulation at the report stage, as `TaskMonitor` does.

    `target` is `Target` (the target's grasp position and object index); `task_status` is
    `TaskStatus` (collision ratio 0: the task has no obstacles). `grasp_positions` (M, 3)
    and `grasp_orientations` (M, 4) are the objects' grasp poses; `start_pose` the hand's
    `[p (3), q (4)]` at the start.
    """

    def __init__(self, grasp_positions, grasp_orientations, targets, switch_schedule,
                 start_pose, success_distance, success_angle, control_period):
        super().__init__()
        self._positions = np.asarray(grasp_positions, float)
        self._orientations = np.asarray(grasp_orientations, float)
        self._targets = tuple(int(t) for t in targets)
        self._schedule = tuple(float(s) for s in switch_schedule)
        if len(self._targets) != len(self._schedule):
            raise ValueError("one target per entry of switch_schedule")
        start_pose = np.asarray(start_pose, float)
        self._start_position, self._start_orientation = start_pose[:3], start_pose[3:7]
        self._success_distance = float(success_distance)
        self._success_angle = float(success_angle)
        self._length_per_radian = self._success_distance / self._success_angle
        period = float(control_period)
        self._update_offset = decide_offset(period)
        self._hand_port = self.DeclareVectorInputPort("hand_pose", PoseState.size)
        self._operator_active_port = self.DeclareVectorInputPort("operator_active", 1)
        self._counts_index = self.DeclareDiscreteState(_COUNTS_SIZE)
        self._measures_index = self.DeclareDiscreteState(2)  # [progress, task time]
        self._target_port = self.DeclareVectorOutputPort(
            "target", Target.size, self._calc_target,
            prerequisites_of_calc={self.discrete_state_ticket(self._counts_index)})
        self._status_port = self.DeclareVectorOutputPort(
            "task_status", TaskStatus.size, self._calc_status,
            prerequisites_of_calc={self.all_state_ticket()})
        self.DeclarePeriodicDiscreteUpdateEvent(period, self._update_offset, self._update)
        self.DeclarePeriodicPublishEvent(period, report_offset(period), self._end_at_success)

    def get_hand_pose_input_port(self):
        return self._hand_port

    def get_operator_active_input_port(self):
        return self._operator_active_port

    def get_target_output_port(self):
        return self._target_port

    def get_task_status_output_port(self):
        return self._status_port

    @property
    def objects(self):
        """The grasp positions (M, 3), the points the task's targets stand for."""
        return self._positions

    @property
    def grasp_orientations(self):
        return self._orientations

    def counts(self, context):
        """The `TaskCounts` held in this system's `context`."""
        return TaskCounts.of_vector(context.get_discrete_state(self._counts_index).value())

    def _calc_target(self, context, output):
        index = self._targets[int(context.get_discrete_state(self._counts_index).value()[
            _STAGE])]
        output.SetFromVector([*self._positions[index], index])

    def _calc_status(self, context, output):
        counts = self.counts(context)
        progress, task_time = context.get_discrete_state(self._measures_index).value()
        status = TaskStatus(np.zeros(TaskStatus.size))
        status.progress, status.stage = progress, counts.stage
        status.success, status.task_time = float(counts.success), task_time
        status.steps = counts.steps
        if counts.steps:
            status.intervention_ratio = counts.acted_steps / counts.steps
        output.SetFromVector(status[:])

    def _progress(self, position, orientation, index):
        return grasp_progress(position, orientation, self._start_position,
                              self._start_orientation, self._positions[index],
                              self._orientations[index], self._length_per_radian)

    def _update(self, context, state):
        counts = self.counts(context)
        if counts.success:
            return EventStatus.DidNothing()
        hand = np.asarray(self._hand_port.Eval(context), float)
        position, orientation = hand[:3], hand[3:7] / np.linalg.norm(hand[3:7])
        acting = self._operator_active_port.Eval(context)[0] > 0.5
        stage = counts.stage
        progress = self._progress(position, orientation, self._targets[stage])
        if stage + 1 < len(self._schedule) and progress >= self._schedule[stage + 1]:
            stage += 1
            progress = self._progress(position, orientation, self._targets[stage])
        target = self._targets[stage]
        success = grasp_success(position, orientation, self._positions[target],
                                self._orientations[target], self._success_distance,
                                self._success_angle)
        state.get_mutable_vector(self._counts_index).set_value(
            [stage, counts.steps + 1, counts.acted_steps + int(acting), 0.0, float(success)])
        # The task time is the tick's: the update runs a fraction of a period after it.
        state.get_mutable_vector(self._measures_index).set_value(
            [progress, context.get_time() - self._update_offset])
        return EventStatus.Succeeded()

    def _end_at_success(self, context):
        if context.get_discrete_state(self._counts_index).value()[_SUCCESS] > 0.5:
            return EventStatus.ReachedTermination(self, SUCCESS_MESSAGE)
        return EventStatus.DidNothing()
