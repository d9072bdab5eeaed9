"""The ``intent_filter`` goal estimator as Drake systems (`pbp_drake.core.intent_filter`),
for positions and for the grasping task's poses."""

import numpy as np

from pbp_drake.core.intent_filter import (
    IntentFilterSettings, filter_step, intent_features, pose_intent_features)
from pbp_drake.core.quaternion import unit_quaternions
from pbp_drake.systems.pbp.maxent_goal_estimator import MaxEntGoalEstimator
from pbp_drake.systems.pbp.pose_maxent_goal_estimator import PoseMaxEntGoalEstimator


class IntentFilterPosterior:
    """What the two intent filter systems share, ahead of the posterior they subclass: the
    filter's step on the features a subclass computes (`_features(context, read, active)`)."""

    _SETTINGS = IntentFilterSettings

    def _targets(self, goals):
        # The goals' rows themselves: the filter reads no HOP targets, and building them (a
        # uniqueness check) would cost O(K log K) a tick.
        return goals

    def _posterior(self, context, read, log_belief):
        if not np.isfinite(read.targets).all():
            raise ValueError(f"{self._goals_port.get_name()} contain NaN or infinite values")
        active = self._active_port.Eval(context)[0] > 0.5
        return filter_step(self._settings, log_belief, self._features(context, read, active),
                           self._period)


class IntentFilterGoalEstimator(IntentFilterPosterior, MaxEntGoalEstimator):
    """The intent filter on the hand's position and heading and the operator's command.

    .. pydrake_system::

        name: IntentFilterGoalEstimator
        input_ports:
        - ee_state
        - goals
        - operator_command
        - operator_active
        output_ports:
        - selected_goal
        - goal_probabilities
        - posterior_clipped

    The ports are `MaxEntGoalEstimator`'s. Each update reads the operator's command and
    yaw rate while it acts, the hand's executed velocity while it is silent, and the hand's
    heading. `settings` is an `IntentFilterSettings`; `margin` and `hold_steps` are the
    selection's hysteresis.
    """

    def _features(self, context, read, active):
        return intent_features(
            read.targets, read.position, read.command if active else read.hand_velocity,
            read.heading, read.yaw_rate if active else 0.0, self._period,
            self._settings.min_speed, active)


class PoseIntentFilterGoalEstimator(IntentFilterPosterior, PoseMaxEntGoalEstimator):
    """The intent filter on the hand's pose and the operator's twist: the grasping task's
    ``intent_filter`` (`pbp_drake.core.intent_filter.pose_intent_features`).

    .. pydrake_system::

        name: PoseIntentFilterGoalEstimator
        input_ports:
        - hand_pose
        - goal_poses
        - operator_twist
        - operator_active
        - shown_goal (optional)
        output_ports:
        - selected_goal
        - goal_probabilities
        - posterior_clipped

    The ports are `PoseMaxEntGoalEstimator`'s, and `shown_goal`, the goal the robot shows
    (`[index]`, -1 or unconnected: none): while the operator acts it is evidence against
    that goal, at `settings.override_rate`. `forward_key` says whether the method lets the
    operator push along the hand's approach axis; without it, the motion is compared with
    each goal's direction across that axis. Each update reads the operator's twist while it
    acts, the hand's executed velocity (and no turn) while it is silent.
    """

    def __init__(self, goal_count, settings, control_period, margin=0.0, hold_steps=1,
                 forward_key=True):
        super().__init__(goal_count, settings, control_period, margin, hold_steps)
        self._forward_key = bool(forward_key)

    def _declare_inputs(self, goal_count):
        super()._declare_inputs(goal_count)
        self._shown_port = self.DeclareVectorInputPort("shown_goal", 1)

    def _features(self, context, read, active):
        poses = read.targets
        shown = (int(self._shown_port.Eval(context)[0]) if self._shown_port.HasValue(context)
                 else -1)
        return pose_intent_features(
            poses[:, :3], unit_quaternions(poses[:, 3:], "goal_poses orientation"),
            read.position, read.orientation,
            read.command if active else read.hand_velocity,
            read.command_angular_velocity if active else np.zeros(3), self._period,
            self._settings.min_speed, active, self._forward_key, shown)
