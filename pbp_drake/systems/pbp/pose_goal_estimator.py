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

    `hand_pose` is the hand's `PoseState`; `goal_poses` the K `GoalPose` rows flattened.
    `operator_twist`, when connected, is the operator's `OperatorTwist`: the direction of
    travel and turn rate are then the operator's, not the hand's, and while it is all zeros
    the selection holds. Connect it whenever a policy moves the hand too, or the selection
    would follow whatever the robot heads for (docs/tasks/grasp.md). At initialisation it
    selects the most probable grasp pose at once.
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
        # No operator input, no new evidence: the selection holds.
        self._select(state, probabilities, previous,
                     hold=previous is not None and operator and not twist.any())
