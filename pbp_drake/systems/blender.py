"""The blender: how the operator's command and the robot policy become the robot's command."""

import numpy as np
from pydrake.systems.framework import LeafSystem

from pbp_drake.core.arbitration import blend, validate_mode


class Blender(LeafSystem):
    """Mixes the operator into the selected policy reference by one of the blending laws.

    .. pydrake_system::

        name: Blender
        input_ports:
        - robot_state
        - references
        - selected_goal (optional)
        - operator_command
        - operator_active
        output_ports:
        - command

    Modes (see `pbp_drake.core.arbitration`): `pbp_continuous` (Alg. 1, `y + u`),
    `pbp_alternated` (Alg. 2, `u` alone while the operator acts), `fixed_alpha`
    (`(1 - alpha) U + alpha P`) and `teleop` (`U`). `robot_state` must be the state sampled
    at the control tick (the builder puts a ZeroOrderHold in front); `references` holds K
    next states and `selected_goal` picks one (goal 0 when unconnected). The output is
    `[position (D), velocity (D)]`. A NaN or infinite operator command raises.
    """

    def __init__(self, mode, dimension, goal_count, control_period, alpha=None):
        super().__init__()
        validate_mode(mode, alpha)
        self._mode = mode
        self._alpha = alpha
        self._dimension = int(dimension)
        self._goal_count = int(goal_count)
        self._period = float(control_period)
        d, k = self._dimension, self._goal_count
        self._robot_state_port = self.DeclareVectorInputPort("robot_state", 2 * d)
        self._references_port = self.DeclareVectorInputPort("references", 2 * k * d)
        self._selected_goal_port = self.DeclareVectorInputPort("selected_goal", 1)
        self._operator_command_port = self.DeclareVectorInputPort("operator_command", d)
        self._operator_active_port = self.DeclareVectorInputPort("operator_active", 1)
        self._command_port = self.DeclareVectorOutputPort("command", 2 * d, self._calc_command)

    @property
    def mode(self):
        return self._mode

    def get_robot_state_input_port(self):
        return self._robot_state_port

    def get_references_input_port(self):
        return self._references_port

    def get_selected_goal_input_port(self):
        return self._selected_goal_port

    def get_operator_command_input_port(self):
        return self._operator_command_port

    def get_operator_active_input_port(self):
        return self._operator_active_port

    def get_command_output_port(self):
        return self._command_port

    def _calc_command(self, context, output):
        d, k = self._dimension, self._goal_count
        selected = 0
        if self._selected_goal_port.HasValue(context):
            selected = int(self._selected_goal_port.Eval(context)[0])
            if not 0 <= selected < k:
                raise ValueError(f"selected_goal {selected} is not one of the {k} goals")
        references = self._references_port.Eval(context).reshape(2, k, d)
        position, velocity = blend(
            self._mode,
            self._robot_state_port.Eval(context)[:d],
            references[0, selected],
            references[1, selected],
            self._operator_command_port.Eval(context),
            self._operator_active_port.Eval(context)[0] > 0.5,
            self._period,
            self._alpha,
        )
        output.SetFromVector(np.concatenate([position, velocity]))
