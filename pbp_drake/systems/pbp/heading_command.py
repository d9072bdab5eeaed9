"""The commanded heading of the end effector: turned by the operator alone."""

import numpy as np
from pydrake.systems.framework import LeafSystem

from pbp_drake.core.coordinates import is_real
from pbp_drake.core.hand_over import check_limit, hand_over
from pbp_drake.systems.ports import OperatorCommand, PortGetters
from pbp_drake.systems.tick import checked_period, decide_offset


class HeadingCommand(PortGetters, LeafSystem):
    """Integrates the operator's yaw rate into the commanded heading.

    .. pydrake_system::

        name: HeadingCommand
        input_ports:
        - operator_command
        output_ports:
        - heading

    Each control period (at the decide stage) the heading moves by `yaw_rate *
    control_period`; with `max_yaw_acceleration` (rad/s^2) the turn rate follows the
    operator's under the hand-over law (`pbp_drake.core.hand_over`). The DMPs never turn
    the robot: in PBP the operator's turning tells the goal estimator where it wants to go.
    With a `max_turn` (rad, an arm's wrist) the heading stays within it of
    `initial_heading`, the turn rate set to 0 at the bound.
    """

    def __init__(self, initial_heading, control_period, max_yaw_acceleration=None,
                 max_turn=None):
        super().__init__()
        self._period = checked_period(control_period)
        if not (is_real(initial_heading) and np.isfinite(initial_heading)):
            raise ValueError(f"initial_heading must be a finite angle (rad), got "
                             f"{initial_heading!r}")
        self._turn_bounds = None
        if max_turn is not None and max_turn != np.inf:  # NaN is refused below
            turn = check_limit(max_turn, "max_turn", "rad")
            self._turn_bounds = (float(initial_heading) - turn, float(initial_heading) + turn)
        self._max_yaw_acceleration = (np.inf if max_yaw_acceleration is None else check_limit(
            max_yaw_acceleration, "max_yaw_acceleration", "rad/s^2"))
        self._command_port = self.DeclareVectorInputPort("operator_command",
                                                         OperatorCommand.size)
        self._heading_index = self.DeclareDiscreteState(np.array([float(initial_heading)]))
        self._yaw_rate_index = self.DeclareDiscreteState(np.zeros(1))
        self._heading_port = self.DeclareStateOutputPort("heading", self._heading_index)
        self.DeclarePeriodicDiscreteUpdateEvent(self._period, decide_offset(self._period),
                                                self._update)

    def _update(self, context, discrete_state):
        heading = discrete_state.get_mutable_value(self._heading_index)
        yaw_rate = discrete_state.get_mutable_value(self._yaw_rate_index)
        wanted = OperatorCommand(self._command_port.Eval(context)).yaw_rate
        # The hand-over law in one dimension.
        heading[:], yaw_rate[:] = hand_over(yaw_rate, heading + wanted * self._period,
                                            [wanted], self._max_yaw_acceleration, np.inf,
                                            self._period)
        if self._turn_bounds is not None:
            low, high = self._turn_bounds
            if not low <= heading[0] <= high:
                heading[0] = min(max(heading[0], low), high)
                yaw_rate[0] = 0.0
