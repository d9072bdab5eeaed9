"""The referee of the multi-goal reaching task: targets, switches, success, metrics; it ends
the simulation at success."""

import dataclasses

import numpy as np
from pydrake.systems.framework import EventStatus, LeafSystem

from pbp_drake.core.coordinates import vector_length
from pbp_drake.core.hand_over import check_limit
from pbp_drake.core.reach_task import reach_progress
from pbp_drake.systems.ports import (
    EeState, PortGetters, Target, TaskStatus, checked_objects, finite_fields, position_of)
from pbp_drake.systems.tick import checked_period, checked_update_offset, report_offset

SUCCESS_MESSAGE = "the target is reached"


@dataclasses.dataclass(frozen=True)
class TaskCounts:
    """The task's whole numbers, as `TaskMonitor.counts` reads them off its state (a
    discrete vector in this order)."""

    stage: int = 0  # target switches so far
    steps: int = 0  # control ticks counted, up to success
    acted_steps: int = 0  # of which the operator acted
    colliding_steps: int = 0  # of which the robot was in collision
    success: bool = False

    @staticmethod
    def of_vector(vector):
        stage, steps, acted_steps, colliding_steps, success = vector
        return TaskCounts(int(stage), int(steps), int(acted_steps), int(colliding_steps),
                          bool(success > 0.5))


_COUNTS_SIZE = len(dataclasses.fields(TaskCounts))
_STAGE, _SUCCESS = 0, 4  # where TaskCounts' stage and success sit in the counts vector


class TaskMonitorBase(PortGetters, LeafSystem):
    """The rules the reaching and the grasping task's referees (`TaskMonitor`,
    `GraspTaskMonitor`) share.

    Inputs: the hand's state (`pose_port`, of `pose_size`), `operator_active` and, with
    `in_collision_port`, an optional `in_collision`; outputs `target` and `task_status`.
    Every control period, `update_offset` after the tick (default: the decide stage), until
    success, it counts the step, computes the progress toward the current target, switches
    to the next of `targets` once progress reaches the next entry of `switch_schedule`, and
    declares success when the hand has reached the current target. `objects` (M, 3) are the
    points the targets stand for. A subclass implements `_read_hand(vector)`,
    `_progress(hand, index)` (a number) and `_reached(hand, index)` (a bool).

    At success a publish event at the report stage returns
    `EventStatus.ReachedTermination`, so `Simulator.AdvanceTo` returns there, before the
    plant moves again; the status then stays frozen.
    """

    _objects_name = "objects"  # the name of `objects` in the subclass's constructor

    def __init__(self, pose_port, pose_size, objects, targets, switch_schedule,
                 control_period, update_offset=None, in_collision_port=False):
        super().__init__()
        self._objects = checked_objects(objects, self._objects_name)
        count = len(self._objects)
        if len(targets) == 0:
            raise ValueError("targets must name at least one object (its index in "
                             f"{self._objects_name}), got none")
        if not all(t in range(count) for t in targets):
            raise ValueError(f"targets must be object indices 0 to {count - 1}, got "
                             f"{list(targets)}")
        self._targets = tuple(int(t) for t in targets)
        self._schedule = tuple(float(s) for s in switch_schedule)
        if not np.isfinite(self._schedule).all():
            raise ValueError(f"switch_schedule must be finite, got {list(self._schedule)}")
        if len(self._targets) != len(self._schedule):
            raise ValueError("one target per entry of switch_schedule")
        period = checked_period(control_period)
        update_offset = self._update_offset = checked_update_offset(update_offset, period)
        end_offset = report_offset(period, update_offset)
        self._hand_port = self.DeclareVectorInputPort(pose_port, pose_size)
        self._operator_active_port = self.DeclareVectorInputPort("operator_active", 1)
        self._in_collision_port = (self.DeclareVectorInputPort("in_collision", 1)
                                   if in_collision_port else None)
        self._counts_index = self.DeclareDiscreteState(_COUNTS_SIZE)
        # [progress, task time]: the status's real-valued entries.
        self._measures_index = self.DeclareDiscreteState(2)
        self.DeclareVectorOutputPort(
            "target", Target.size, self._calc_target,
            prerequisites_of_calc={self.discrete_state_ticket(self._counts_index)})
        self.DeclareVectorOutputPort(
            "task_status", TaskStatus.size, self._calc_status,
            prerequisites_of_calc={self.all_state_ticket()})
        self.DeclarePeriodicDiscreteUpdateEvent(period, update_offset, self._update)
        self.DeclarePeriodicPublishEvent(period, end_offset, self._end_at_success)

    @property
    def objects(self):
        """The points (M, 3) the task's targets stand for."""
        return self._objects

    def counts(self, context):
        """The `TaskCounts` held in this system's `context`."""
        return TaskCounts.of_vector(self._count_vector(context))

    def _count_vector(self, context):
        return context.get_discrete_state(self._counts_index).value()

    def _calc_target(self, context, output):
        index = self._targets[int(self._count_vector(context)[_STAGE])]
        target = Target(np.empty(Target.size))
        target.x, target.y, target.z = self._objects[index]
        target.index = index
        output.SetFromVector(target[:])

    def _calc_status(self, context, output):
        counts = self.counts(context)
        progress, task_time = context.get_discrete_state(self._measures_index).value()
        status = TaskStatus(np.zeros(TaskStatus.size))
        status.progress = progress
        status.stage = counts.stage
        status.success = float(counts.success)
        status.task_time = task_time
        status.steps = counts.steps
        if counts.steps:
            status.intervention_ratio = counts.acted_steps / counts.steps
            status.collision_ratio = counts.colliding_steps / counts.steps
        output.SetFromVector(status[:])

    def _update(self, context, state):
        counts = self.counts(context)
        if counts.success:
            return EventStatus.DidNothing()
        hand = self._read_hand(self._hand_port.Eval(context))
        acting = self._operator_active_port.Eval(context)[0] > 0.5
        colliding = (self._in_collision_port is not None
                     and self._in_collision_port.HasValue(context)
                     and self._in_collision_port.Eval(context)[0] > 0.5)
        stage = counts.stage
        progress = self._progress(hand, self._targets[stage])
        if stage + 1 < len(self._schedule) and progress >= self._schedule[stage + 1]:
            stage += 1
            progress = self._progress(hand, self._targets[stage])
        success = self._reached(hand, self._targets[stage])
        # DiscreteValues.set_value: one pybind call a group (get_mutable_vector's: two).
        state.set_value(self._counts_index,
                        [stage, counts.steps + 1, counts.acted_steps + int(acting),
                         counts.colliding_steps + int(colliding), float(success)])
        # The task time is the tick's: the update runs a fraction of a period after it.
        state.set_value(self._measures_index,
                        [progress, context.get_time() - self._update_offset])
        return EventStatus.Succeeded()

    def _end_at_success(self, context):
        if self._count_vector(context)[_SUCCESS] > 0.5:
            return EventStatus.ReachedTermination(self, SUCCESS_MESSAGE)
        return EventStatus.DidNothing()


class TaskMonitor(TaskMonitorBase):
    """Switches the target at the progress schedule, keeps the task's metrics, and ends the
    simulation at success (the rules of `TaskMonitorBase`).

    .. pydrake_system::

        name: TaskMonitor
        input_ports:
        - ee_state
        - operator_active
        - in_collision (optional)
        output_ports:
        - target
        - task_status

    `ee_state` is `EeState`; progress is measured toward the current target from the end
    effector's `start`, and success is the end effector within `success_distance` of it.
    `target` is `Target` (`[position (3), object index]`); `task_status` is `TaskStatus`
    (`[progress, stage (number of switches so far), success (0/1), task time (s, the time
    of the last tick counted: at success, the tick that reached the target), intervention ratio
    (steps with operator input / steps of the task), steps, collision ratio (steps with
    `in_collision` / steps; 0 when unconnected)]`).
    """

    def __init__(self, objects, targets, switch_schedule, start, success_distance,
                 control_period, update_offset=None):
        super().__init__("ee_state", EeState.size, objects, targets, switch_schedule,
                         control_period, update_offset, in_collision_port=True)
        self._start = np.asarray(start, dtype=float)
        if self._start.shape != (3,) or not np.isfinite(self._start).all():
            raise ValueError(f"start must be 3 finite numbers [x, y, z], got {start!r}")
        self._success_distance = check_limit(success_distance, "success_distance", "m")

    def _read_hand(self, vector):
        return position_of(EeState(finite_fields(vector, "ee_state", EeState.get_fields())))

    def _progress(self, hand, index):
        return reach_progress(hand, self._start, self._objects[index])

    def _reached(self, hand, index):
        return bool(vector_length(hand - self._objects[index]) <= self._success_distance)
