"""The ``pose`` goal estimator as a Drake system: which of K grasp poses the operator means."""

import numpy as np

from pbp_drake.core.goal_estimation import GoalEstimatorSettings
from pbp_drake.core.grasp_estimation import pose_probabilities
from pbp_drake.systems.pbp.goal_estimator import GoalEstimatorBase
from pbp_drake.systems.ports import GoalPose, OperatorTwist, PoseState


class PoseGoalEstimator(GoalEstimatorBase):
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
    `[index]` and `goal_probabilities` the K probabilities (`GoalEstimatorBase`). At
    initialisation it selects the most probable grasp pose at once (no hysteresis); each
    update recomputes the probabilities and moves the selection with the hysteresis.
    """

    def __init__(self, goal_count, settings, control_period):
        if not isinstance(settings, GoalEstimatorSettings) or settings.method != "pose":
            raise ValueError("settings must be a GoalEstimatorSettings with method 'pose'")
        super().__init__(goal_count, settings, control_period)
        self.DeclareInitializationDiscreteUpdateEvent(
            lambda context, state: self._estimate(context, state, None))

    def _declare_inputs(self, goal_count):
        self._hand_port = self.DeclareVectorInputPort("hand_pose", PoseState.size)
        self._goals_port = self.DeclareVectorInputPort("goal_poses",
                                                       goal_count * GoalPose.size)
        self._twist_port = self.DeclareVectorInputPort("operator_twist", OperatorTwist.size)

    def _update(self, context, state):
        self._estimate(context, state, self._previous(context.get_discrete_state()))

    def _estimate(self, context, state, previous):
        hand = np.asarray(self._hand_port.Eval(context), float)
        goals = np.asarray(self._goals_port.Eval(context), float).reshape(
            self._goal_count, GoalPose.size)
        operator = self._twist_port.HasValue(context)
        twist = np.asarray(self._twist_port.Eval(context), float) if operator else hand[7:13]
        probabilities = pose_probabilities(
            self._settings, goals[:, :3], goals[:, 3:], hand[:3],
            hand[3:7] / np.linalg.norm(hand[3:7]), twist[:3], twist[3:])
        # The operator gives no input: no new evidence of intent, so the selection holds
        # (the probabilities still follow the hand).
        self._select(state, probabilities, previous,
                     hold=previous is not None and operator and not twist.any())
