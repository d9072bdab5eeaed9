"""HOP's and predict-then-assist's assistance as a Drake system
(`pbp_drake.core.hindsight_optimization.assisted_command`)."""

import numpy as np
from pydrake.systems.framework import LeafSystem

from pbp_drake.core.hindsight_optimization import (
    HopSettings, assisted_command, check_assistance, hop_targets)
from pbp_drake.systems.ports import PortGetters, checked_count, checked_settings
from pbp_drake.systems.tick import checked_period


class HopAssistanceBase(PortGetters, LeafSystem):
    """What `HopAssistance` and `PoseHopAssistance` share: the method, the settings, the
    control period and the checks of them."""

    def __init__(self, method, goal_count, settings, control_period):
        super().__init__()
        check_assistance(method)
        self._settings = checked_settings(settings, HopSettings)
        self._method = method
        self._goal_count = checked_count(goal_count, "goal_count")
        self._period = checked_period(control_period)

    @property
    def method(self):
        return self._method

    @property
    def settings(self):
        return self._settings


class HopAssistance(HopAssistanceBase):
    """The command of ``hop`` or ``predict_then_assist`` in the position tasks.

    .. pydrake_system::

        name: HopAssistance
        input_ports:
        - robot_state
        - goals
        - operator_command
        - goal_probabilities
        output_ports:
        - command

    `robot_state` is the hand's `[p (3), v (3)]` sampled at the tick, `goals` the K goals
    flattened `(K, 3)`, `operator_command` the operator's velocity `u` (3),
    `goal_probabilities` the belief (`MaxEntGoalEstimator`'s). `command` is
    `[p + (u + a) control_period, u + a]`, `a` the assistance of `assisted_command`, for
    the `HandOver`. A NaN or infinite command raises.
    """

    def __init__(self, method, goal_count, settings, control_period):
        super().__init__(method, goal_count, settings, control_period)
        k = self._goal_count
        self._robot_state_port = self.DeclareVectorInputPort("robot_state", 6)
        self._goals_port = self.DeclareVectorInputPort("goals", 3 * k)
        self._operator_command_port = self.DeclareVectorInputPort("operator_command", 3)
        self._probabilities_port = self.DeclareVectorInputPort("goal_probabilities", k)
        # A function of the inputs alone: not redone between the control ticks.
        self._command_port = self.DeclareVectorOutputPort(
            "command", 6, self._calc_command,
            prerequisites_of_calc={self.all_input_ports_ticket()})

    def _calc_command(self, context, output):
        position = self._robot_state_port.Eval(context)[:3]
        targets = hop_targets(self._goals_port.Eval(context).reshape(self._goal_count, 3))
        command = assisted_command(self._method, self._settings, targets,
                                   self._probabilities_port.Eval(context), position,
                                   self._operator_command_port.Eval(context))
        output.SetFromVector(np.concatenate([position + command.velocity * self._period,
                                             command.velocity]))
