"""Goal groups as Drake systems, between the goal estimator and the DMP bank: positions
(`GoalGrouping`) and poses (`PoseGoalGrouping`, the grasping task)."""

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import LeafSystem, ValueProducer

from pbp_drake.core.coordinates import is_real
from pbp_drake.core.goal_estimation import GoalEstimatorSettings
from pbp_drake.core.goal_groups import NO_GOAL, group_target, pose_group_target
from pbp_drake.systems.ports import (
    EeState, GoalPose, PortGetters, PoseState, checked_count, checked_settings, goal_index)
from pbp_drake.systems.tick import checked_period, decide_offset


class GoalGrouping(PortGetters, LeafSystem):
    """Steers the selected goal's DMP to the group of goals the estimate cannot yet tell
    apart, and says which goal the robot shows (`pbp_drake.core.goal_groups`).

    .. pydrake_system::

        name: GoalGrouping
        input_ports:
        - goals
        - goal_probabilities
        - selected_goal
        - ee_state
        output_ports:
        - followed_goals
        - shown_goal

    The rules are docs/concepts/goal-estimators.md's ("Many goals: goal groups");
    `settings` is the estimator's `GoalEstimatorSettings`. `goals` is the K goals `(K, 3)`
    row-major. `followed_goals` is `goals` with the selected goal's row moved to the
    group's point while the robot has not committed; `shown_goal` is `[index]`, the
    selected goal once committed, else `NO_GOAL` (-1).
    """

    # The goals' input and numbers per goal, the hand's input and its size, the output.
    _GOALS, _WIDTH, _HAND, _HAND_SIZE = "goals", 3, "ee_state", EeState.size
    _FOLLOWED_NAME = "followed_goals"

    def __init__(self, goal_count, settings, control_period):
        super().__init__()
        self._goal_count = k = checked_count(goal_count, "goal_count")
        width = self._WIDTH
        settings = checked_settings(settings, GoalEstimatorSettings)
        self._settings = (float(settings.group_mass), float(settings.commit_radius),
                          float(settings.commit_probability))
        self._goals_port = self.DeclareVectorInputPort(self._GOALS, width * k)
        self._probabilities_port = self.DeclareVectorInputPort("goal_probabilities", k)
        self._selected_port = self.DeclareVectorInputPort("selected_goal", 1)
        self._hand_port = self.DeclareVectorInputPort(self._HAND, self._HAND_SIZE)
        period = checked_period(control_period)
        self._committed_index = self.DeclareDiscreteState(np.array([float(NO_GOAL)]))
        self.DeclarePeriodicDiscreteUpdateEvent(period, decide_offset(period), self._commit)
        # [followed goals (width K), shown index]: computed once for both outputs.
        self._target = self.DeclareCacheEntry(
            "followed goals and the shown goal",
            ValueProducer(allocate=lambda: AbstractValue.Make(np.zeros(width * k + 1)),
                          calc=self._calc_target),
            prerequisites_of_calc={self.all_input_ports_ticket(), self.xd_ticket()})
        self.DeclareVectorOutputPort(
            self._FOLLOWED_NAME, width * k,
            lambda context, output: output.SetFromVector(self._target.Eval(context)[:-1]),
            prerequisites_of_calc={self._target.ticket()})
        self.DeclareVectorOutputPort(
            "shown_goal", 1,
            lambda context, output: output.SetAtIndex(0, self._target.Eval(context)[-1]),
            prerequisites_of_calc={self._target.ticket()})

    def _group(self, goals, probabilities, selected, hand, committed):
        return group_target(goals, probabilities, selected, *self._settings, hand=hand[:3],
                            committed=committed)

    def _commit(self, context, discrete_state):
        discrete_state.set_value(self._committed_index, [self._target.Eval(context)[-1]])

    def _calc_target(self, context, value):
        width = self._WIDTH
        goals = self._goals_port.Eval(context).reshape(self._goal_count, width)
        selected = goal_index(self._selected_port, context, self._goal_count)
        target = self._group(
            goals, self._probabilities_port.Eval(context), selected,
            self._hand_port.Eval(context),
            int(context.get_discrete_state(self._committed_index).value()[0]))
        result = value.get_mutable_value()
        result[:-1] = goals.reshape(-1)
        result[width * selected:width * (selected + 1)] = target.point
        result[-1] = target.shown


class PoseGoalGrouping(GoalGrouping):
    """`GoalGrouping` for pose goals (the grasping task): the group's point is a pose.

    .. pydrake_system::

        name: PoseGoalGrouping
        input_ports:
        - goal_poses
        - goal_probabilities
        - selected_goal
        - hand_pose
        output_ports:
        - followed_poses
        - shown_goal

    `goal_poses` is K `GoalPose` rows flattened; `hand_pose` a `PoseState`. Distances are
    pose errors with `metres_per_radian` (the task's success distance over its angle).
    """

    _GOALS, _WIDTH, _HAND, _HAND_SIZE = "goal_poses", GoalPose.size, "hand_pose", PoseState.size
    _FOLLOWED_NAME = "followed_poses"

    def __init__(self, goal_count, settings, control_period, metres_per_radian):
        if not (is_real(metres_per_radian) and np.isfinite(metres_per_radian)
                and metres_per_radian >= 0.0):
            raise ValueError(f"metres_per_radian must be a finite number >= 0, got "
                             f"{metres_per_radian!r}")
        self._metres_per_radian = float(metres_per_radian)
        super().__init__(goal_count, settings, control_period)

    def _group(self, goals, probabilities, selected, hand, committed):
        return pose_group_target(goals, probabilities, selected, *self._settings,
                                 self._metres_per_radian, hand=hand[:7], committed=committed)
