"""The hand-over law as a Drake system, between the blender and the robot."""

import numpy as np
from pydrake.systems.framework import LeafSystem

from pbp_drake.core.hand_over import check_limit, hand_over
from pbp_drake.systems.ports import PortGetters
from pbp_drake.systems.tick import checked_period, report_offset


class HandOver(PortGetters, LeafSystem):
    """Passes the blender's reference on with its velocity changing at most
    `max_acceleration * control_period` per tick and its speed at most `max_speed`
    (`pbp_drake.core.hand_over`).

    .. pydrake_system::

        name: HandOver
        input_ports:
        - reference
        output_ports:
        - command

    `reference` and `command` are `[position (D), velocity (D)]`. The command is the
    system's state, so it holds between ticks; it starts at `initial_position`, at rest.

    It updates at the report stage of each tick (`pbp_drake.systems.tick.report_offset`),
    after the DMP bank, the goal estimator and the operator have decided: the reference it
    reads is the one of the same tick, and the robot follows the result from that tick on
    (no plant step lies between the tick and its report stage).
    """

    def __init__(self, initial_position, max_acceleration, max_speed, control_period):
        super().__init__()
        initial_position = np.asarray(initial_position, dtype=float).reshape(-1)
        if not np.isfinite(initial_position).all():
            raise ValueError(f"initial_position must be finite, got {initial_position}")
        self._max_acceleration = check_limit(max_acceleration, "max_acceleration", "m/s^2")
        self._max_speed = check_limit(max_speed, "max_speed", "m/s")
        self._period = checked_period(control_period)
        self._dimension = d = initial_position.size
        self._reference_port = self.DeclareVectorInputPort("reference", 2 * d)
        self._state_index = index = self.DeclareDiscreteState(
            np.concatenate([initial_position, np.zeros(d)]))
        self._command_port = self.DeclareStateOutputPort("command", index)
        self.DeclarePeriodicDiscreteUpdateEvent(
            self._period, report_offset(self._period), self._update)

    def _update(self, context, discrete_state):
        d = self._dimension
        reference = self._reference_port.Eval(context)
        # One pybind call for the group's array (get_mutable_vector and its value: two).
        state = discrete_state.get_mutable_value(self._state_index)
        position, velocity = hand_over(state[d:], reference[:d], reference[d:],
                                       self._max_acceleration, self._max_speed,
                                       self._period)
        state[:d] = position
        state[d:] = velocity
