"""The ``pose`` goal estimator as a Drake system: which of K grasp poses the operator means."""

import dataclasses

import numpy as np
from pydrake.systems.framework import LeafSystem

from pbp_drake.core.goal_estimation import (
    GoalEstimatorSettings, SelectionMemory, update_selection)
from pbp_drake.core.grasp_estimation import pose_probabilities
from pbp_drake.systems.ports import GoalPose, OperatorTwist, PortGetters, PoseState
from pbp_drake.systems.tick import decide_offset


class PoseGoalEstimator(PortGetters, LeafSystem):
    """Estimates the intended grasp pose every control period
    (`pbp_drake.core.grasp_estimation.pose_probabilities` and the shipped hysteresis,
    `goal_estimation.update_selection`).

    .. pydrake_system::

        name: PoseGoalEstimator
        input_ports:
        - hand_pose
        - goal_poses
        - operator_twist (optional)
        output_ports:
        - selected_goal
        - goal_probabilities

    `hand_pose` is the hand's `PoseState` (pose and world-frame twist); `goal_poses` the K
    `GoalPose` rows `[x, y, z, qw, qx, qy, qz]` flattened. `operator_twist`, when
    connected, is the operator's `OperatorTwist` (world frame): the estimator's direction
    of travel and turn rate are then the operator's, not the hand's, and while the operator
    gives no input (all zeros) the selection holds. Connect it whenever a policy moves the
    hand too: the hand's own twist is then mostly the selected DMP's, and would hold the
    selection on whatever the robot heads for (docs/tasks/grasp.md). Unconnected, the
    hand's twist is read and the selection follows it at every update. `selected_goal` is
    `[index]` and `goal_probabilities` the K probabilities, read from the state as
    `GoalEstimator`'s. At initialisation it selects the most probable grasp pose at once
    (no hysteresis); each update, at the decide stage of the tick, it recomputes the
    probabilities and moves the selection with the shipped hysteresis.
    """

    def __init__(self, goal_count, settings, control_period):
        super().__init__()
        if not isinstance(settings, GoalEstimatorSettings) or settings.method != "pose":
            raise ValueError("settings must be a GoalEstimatorSettings with method 'pose'")
        settings.validate()
        k = self._goal_count = int(goal_count)
        # A copy: the settings are a plain (mutable) dataclass the caller may change later.
        self._settings = dataclasses.replace(settings)
        self._hand_port = self.DeclareVectorInputPort("hand_pose", PoseState.size)
        self._goals_port = self.DeclareVectorInputPort("goal_poses", k * GoalPose.size)
        self._twist_port = self.DeclareVectorInputPort("operator_twist", OperatorTwist.size)
        self._selected_index = self.DeclareDiscreteState(np.zeros(1))
        self._probabilities_index = self.DeclareDiscreteState(np.full(k, 1.0 / k))
        # [challenger, count] of the hysteresis (`SelectionMemory`); -1: none yet.
        self._memory_index = self.DeclareDiscreteState(np.array([-1.0, 0.0]))
        self._selected_port = self.DeclareStateOutputPort("selected_goal",
                                                          self._selected_index)
        self._probabilities_port = self.DeclareStateOutputPort("goal_probabilities",
                                                               self._probabilities_index)
        self.DeclareInitializationDiscreteUpdateEvent(
            lambda context, state: self._estimate(context, state, None))
        self.DeclarePeriodicDiscreteUpdateEvent(float(control_period),
                                                decide_offset(control_period), self._update)

    def _update(self, context, state):
        challenger, count = context.get_discrete_state(self._memory_index).value()
        selected = int(context.get_discrete_state(self._selected_index).value()[0])
        self._estimate(context, state, SelectionMemory(selected, int(challenger), int(count)))

    def _estimate(self, context, state, memory):
        hand = np.asarray(self._hand_port.Eval(context), float)
        goals = np.asarray(self._goals_port.Eval(context), float).reshape(
            self._goal_count, GoalPose.size)
        operator = self._twist_port.HasValue(context)
        twist = np.asarray(self._twist_port.Eval(context), float) if operator else hand[7:13]
        probabilities = pose_probabilities(
            self._settings, goals[:, :3], goals[:, 3:], hand[:3],
            hand[3:7] / np.linalg.norm(hand[3:7]), twist[:3], twist[3:])
        if memory is not None and operator and not twist.any():
            # The operator gives no input: no new evidence of intent, so the selection
            # holds (the probabilities still follow the hand).
            memory = SelectionMemory(memory.selected)
        else:
            memory = update_selection(probabilities, memory, self._settings.margin,
                                      self._settings.hold_steps)
        state.get_mutable_vector(self._selected_index).set_value([memory.selected])
        state.get_mutable_vector(self._probabilities_index).set_value(probabilities)
        state.get_mutable_vector(self._memory_index).set_value(
            [memory.challenger, memory.count])
