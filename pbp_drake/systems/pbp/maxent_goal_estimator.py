"""HOP's goal posterior as a Drake system (`pbp_drake.core.hindsight_optimization`), or
with an `operator_speed` the ``maxent_command`` one (`pbp_drake.core.maxent_command`)."""

import typing

import numpy as np

from pbp_drake.core.hindsight_optimization import (
    HopSettings, hop_targets, uniform_log_belief, update_posterior)
from pbp_drake.core.maxent_command import intent_evidence, update_intent_posterior
from pbp_drake.systems.pbp.goal_estimator import GoalEstimatorBase
from pbp_drake.systems.ports import EeState, OperatorCommand, finite_fields


class PosteriorInputs(typing.NamedTuple):
    """What an update reads: the `targets`, the hand's `position`, the operator's
    `command` velocity, the hand's executed `hand_velocity`; with orientations the hand's
    `orientation`, the operator's `command_angular_velocity` and the hand's
    `hand_angular_velocity`; without, the hand's `heading` and the operator's `yaw_rate`."""

    targets: typing.Any
    position: np.ndarray
    command: np.ndarray
    hand_velocity: np.ndarray
    orientation: typing.Optional[np.ndarray] = None
    command_angular_velocity: typing.Optional[np.ndarray] = None
    hand_angular_velocity: typing.Optional[np.ndarray] = None
    heading: typing.Optional[float] = None
    yaw_rate: float = 0.0


class CommandPosteriorBase(GoalEstimatorBase):
    """What `MaxEntGoalEstimator` and `PoseMaxEntGoalEstimator` share: the log belief and
    whether the last update was clipped (output `posterior_clipped`). A subclass declares
    its input ports (`_declare_inputs`, `operator_active` among them) and reads them
    (`_inputs(context) -> PosteriorInputs`). `operator_speed` None: HOP's update, on the
    operator's command alone; a speed (m/s): the ``maxent_command`` likelihood, on the
    operator's command while it acts and the hand's executed motion while it is silent."""

    _SETTINGS = HopSettings

    def __init__(self, goal_count, settings, control_period, margin=0.0, hold_steps=1,
                 operator_speed=None):
        if operator_speed is not None and not (np.isfinite(operator_speed)
                                               and operator_speed > 0.0):
            raise ValueError(f"operator_speed must be positive, got {operator_speed!r}")
        self._operator_speed = None if operator_speed is None else float(operator_speed)
        super().__init__(goal_count, settings, control_period, margin, hold_steps)
        self._log_belief_index = self.DeclareDiscreteState(uniform_log_belief(self._goal_count))
        self._clipped_index = self.DeclareDiscreteState(np.zeros(1))
        self._clipped_port = self.DeclareStateOutputPort("posterior_clipped",
                                                         self._clipped_index)

    def _update(self, context, discrete_state):
        state = context.get_discrete_state()
        read = self._inputs(context)
        update = self._posterior(context, read, state.value(self._log_belief_index))
        self._select(discrete_state, update.probabilities, self._previous(state))
        discrete_state.set_value(self._log_belief_index, update.log_belief)
        discrete_state.set_value(self._clipped_index, [1.0 if update.clipped else 0.0])

    def _posterior(self, context, read, log_belief):
        """This tick's update of the belief (with `log_belief`, `probabilities`, `clipped`)."""
        if self._operator_speed is None:
            return update_posterior(self._settings, read.targets, log_belief, read.position,
                                    read.command, read.orientation,
                                    read.command_angular_velocity)
        # Silent, the operator lets the robot go on: its motion is the implicit command.
        active = self._active_port.Eval(context)[0] > 0.5
        evidence = intent_evidence(
            self._settings, read.targets, read.position,
            read.command if active else read.hand_velocity, self._operator_speed,
            read.heading, read.yaw_rate if active else 0.0, read.orientation,
            read.command_angular_velocity if active else read.hand_angular_velocity)
        return update_intent_posterior(self._settings, read.targets, log_belief, evidence)


class MaxEntGoalEstimator(CommandPosteriorBase):
    """HOP's goal posterior on the hand's position and the operator's velocity command
    (`pbp_drake.core.hindsight_optimization.update_posterior`): the ``maxent_command`` goal
    estimator of PBP, and the belief of the ``hop`` and ``predict_then_assist`` methods.

    .. pydrake_system::

        name: MaxEntGoalEstimator
        input_ports:
        - ee_state
        - goals
        - operator_command
        - operator_active (read with operator_speed)
        output_ports:
        - selected_goal
        - goal_probabilities
        - posterior_clipped

    `ee_state` is `EeState`, `goals` the K goals flattened `(K, 3)`, `operator_command` an
    `OperatorCommand`. The belief starts uniform; each update moves it by `-(Q_g - V_g)`
    (with `operator_speed`: by `maxent_command`'s evidence) and clips it at
    `settings.max_probability`; the selection moves with the hysteresis of `margin` and
    `hold_steps` (0 and 1: at once). `posterior_clipped` is `[1]` when the last update was
    clipped, else `[0]`.
    """

    def _declare_inputs(self, goal_count):
        self._ee_state_port = self.DeclareVectorInputPort("ee_state", EeState.size)
        self._goals_port = self.DeclareVectorInputPort("goals", 3 * goal_count)
        self._command_port = self.DeclareVectorInputPort("operator_command",
                                                         OperatorCommand.size)
        self._active_port = self.DeclareVectorInputPort("operator_active", 1)

    def _targets(self, goals):
        """`PosteriorInputs.targets` of the goals (K, 3): one HOP target each."""
        return hop_targets(goals)

    def _inputs(self, context):
        targets = self._targets(self._goals_port.Eval(context).reshape(self._goal_count, 3))
        hand = finite_fields(self._ee_state_port.Eval(context), "ee_state", EeState.get_fields())
        command = finite_fields(self._command_port.Eval(context), "operator_command",
                                OperatorCommand.get_fields())
        return PosteriorInputs(targets, hand[:3], command[:3], hand[3:6],
                               heading=float(EeState(hand).heading),
                               yaw_rate=float(OperatorCommand(command).yaw_rate))
