"""The referee of the multi-goal reaching task: targets, switches, success, metrics."""

import numpy as np
from pydrake.systems.framework import LeafSystem

from pbp_drake.core.reach_task import reach_progress

# Layout of the `task_status` output.
PROGRESS, STAGE, SUCCESS, TASK_TIME, INTERVENTION_RATIO, STEPS, COLLISION_RATIO = range(7)
TASK_STATUS_FIELDS = ("progress", "stage", "success", "task_time", "intervention_ratio",
                      "steps", "collision_ratio")


class TaskMonitor(LeafSystem):
    """Switches the target at the progress schedule and keeps the task's metrics.

    .. pydrake_system::

        name: TaskMonitor
        input_ports:
        - ee_state
        - operator_active
        - in_collision (optional)
        output_ports:
        - target
        - task_status

    `ee_state` is `[p (3), v (3), heading, heading_rate]`. Every control period, until
    success: count the step (and whether the operator acted), compute the progress toward
    the current target from the end effector's start, switch to the next target of
    `targets` once progress reaches the next entry of `switch_schedule`, and declare success
    when the end effector is within `success_distance` of the current target.

    `target` is `[position (3), object index]`; `task_status` is `[progress, stage (number
    of switches so far), success (0/1), task time (s, frozen at success), intervention
    ratio (steps with operator input / steps of the task), steps, collision ratio (steps
    with `in_collision` / steps; 0 when unconnected)]`.
    """

    def __init__(self, objects, targets, switch_schedule, start, success_distance,
                 control_period, update_offset=0.0):
        super().__init__()
        self._objects = np.asarray(objects, dtype=float)
        self._targets = tuple(int(t) for t in targets)
        self._schedule = tuple(float(s) for s in switch_schedule)
        if len(self._targets) != len(self._schedule):
            raise ValueError("one target per entry of switch_schedule")
        self._start = np.asarray(start, dtype=float)
        self._success_distance = float(success_distance)
        self._ee_state_port = self.DeclareVectorInputPort("ee_state", 8)
        self._operator_active_port = self.DeclareVectorInputPort("operator_active", 1)
        self._in_collision_port = self.DeclareVectorInputPort("in_collision", 1)
        self._status_index = self.DeclareDiscreteState(len(TASK_STATUS_FIELDS))
        # Steps with operator input and steps in collision.
        self._counts_index = self.DeclareDiscreteState(2)
        self._target_port = self.DeclareVectorOutputPort(
            "target", 4, self._calc_target,
            prerequisites_of_calc={self.discrete_state_ticket(self._status_index)})
        self._status_port = self.DeclareStateOutputPort("task_status", self._status_index)
        self.DeclarePeriodicDiscreteUpdateEvent(control_period, update_offset, self._update)

    def get_ee_state_input_port(self):
        return self._ee_state_port

    def get_operator_active_input_port(self):
        return self._operator_active_port

    def get_in_collision_input_port(self):
        return self._in_collision_port

    def get_target_output_port(self):
        return self._target_port

    def get_task_status_output_port(self):
        return self._status_port

    @property
    def objects(self):
        return self._objects

    def _calc_target(self, context, output):
        stage = int(context.get_discrete_state(self._status_index).value()[STAGE])
        index = self._targets[stage]
        output.SetFromVector(np.append(self._objects[index], index))

    def _update(self, context, discrete_state):
        status = context.get_discrete_state(self._status_index).value().copy()
        if status[SUCCESS] > 0.5:
            return
        position = self._ee_state_port.Eval(context)[:3]
        acting = self._operator_active_port.Eval(context)[0] > 0.5
        colliding = (self._in_collision_port.HasValue(context)
                     and self._in_collision_port.Eval(context)[0] > 0.5)
        # The ratios come from whole counts of steps, kept beside the status.
        counts = context.get_discrete_state(self._counts_index).value() + [acting, colliding]
        discrete_state.get_mutable_vector(self._counts_index).set_value(counts)
        status[STEPS] += 1
        status[INTERVENTION_RATIO], status[COLLISION_RATIO] = counts / status[STEPS]
        stage = int(status[STAGE])
        target = self._objects[self._targets[stage]]
        progress = reach_progress(position, self._start, target)
        if stage + 1 < len(self._schedule) and progress >= self._schedule[stage + 1]:
            stage += 1
            target = self._objects[self._targets[stage]]
            progress = reach_progress(position, self._start, target)
        status[STAGE] = stage
        status[PROGRESS] = progress
        status[TASK_TIME] = context.get_time()
        if np.linalg.norm(position - target) <= self._success_distance:
            status[SUCCESS] = 1.0
        discrete_state.get_mutable_vector(self._status_index).set_value(status)
