"""HOP's goal posterior on the hand's pose as a Drake system."""

import numpy as np

from pbp_drake.core.hindsight_optimization import hop_targets
from pbp_drake.systems.pbp.maxent_goal_estimator import CommandPosteriorBase, PosteriorInputs
from pbp_drake.systems.ports import (
    GoalPose, OperatorTwist, PoseState, finite_fields, finite_pose_state)


class PoseMaxEntGoalEstimator(CommandPosteriorBase):
    """HOP's goal posterior with position and orientation terms, on the hand's pose and the
    operator's twist: the grasping task's ``maxent_command`` goal estimator, and the belief
    of its ``hop`` and ``predict_then_assist`` methods (`MaxEntGoalEstimator` with the pose).

    .. pydrake_system::

        name: PoseMaxEntGoalEstimator
        input_ports:
        - hand_pose
        - goal_poses
        - operator_twist
        - operator_active (read with operator_speed)
        output_ports:
        - selected_goal
        - goal_probabilities
        - posterior_clipped

    `hand_pose` is the hand's `PoseState`, `goal_poses` the K `GoalPose` rows flattened,
    `operator_twist` an `OperatorTwist`. A goal's cost adds `settings.rotation_weight` times
    the rotation term to the translation term. Updates, selection and outputs are
    `MaxEntGoalEstimator`'s.
    """

    def _declare_inputs(self, goal_count):
        self._hand_port = self.DeclareVectorInputPort("hand_pose", PoseState.size)
        self._goals_port = self.DeclareVectorInputPort("goal_poses",
                                                       goal_count * GoalPose.size)
        self._twist_port = self.DeclareVectorInputPort("operator_twist", OperatorTwist.size)
        self._active_port = self.DeclareVectorInputPort("operator_active", 1)

    def _targets(self, poses):
        """`PosteriorInputs.targets` of the goal poses (K, 7): one HOP target each."""
        return hop_targets(poses[:, :3], poses[:, 3:])

    def _inputs(self, context):
        poses = self._goals_port.Eval(context).reshape(self._goal_count, GoalPose.size)
        hand = finite_pose_state(self._hand_port.Eval(context), "hand_pose")
        twist = finite_fields(self._twist_port.Eval(context), "operator_twist",
                              OperatorTwist.get_fields())
        orientation = hand[3:7] / np.linalg.norm(hand[3:7])
        return PosteriorInputs(self._targets(poses), hand[:3], twist[:3], hand[7:10],
                               orientation, twist[3:], hand[10:13])
