"""The commanded heading of the end effector: turned by the operator alone."""

import numpy as np
from pydrake.systems.framework import LeafSystem


class HeadingCommand(LeafSystem):
    """Integrates the operator's yaw rate into the commanded heading.

    .. pydrake_system::

        name: HeadingCommand
        input_ports:
        - operator_command
        output_ports:
        - heading

    `operator_command` is `[vx, vy, vz, yaw_rate]`; each control period the heading moves
    by `yaw_rate * control_period`. The DMPs never turn the robot: in PBP the operator's
    turning is how it tells the goal estimator where it wants to go. Like the DMP bank, it
    updates `update_offset` after the tick to use the operator's command of that tick.
    """

    def __init__(self, initial_heading, control_period, update_offset=0.0):
        super().__init__()
        self._period = float(control_period)
        self._command_port = self.DeclareVectorInputPort("operator_command", 4)
        index = self.DeclareDiscreteState(np.array([float(initial_heading)]))
        self._heading_port = self.DeclareStateOutputPort("heading", index)
        self.DeclarePeriodicDiscreteUpdateEvent(self._period, update_offset, self._update)

    def get_operator_command_input_port(self):
        return self._command_port

    def get_heading_output_port(self):
        return self._heading_port

    def _update(self, context, discrete_state):
        heading = context.get_discrete_state_vector().value()[0]
        yaw_rate = self._command_port.Eval(context)[3]
        discrete_state.get_mutable_vector().set_value([heading + yaw_rate * self._period])
