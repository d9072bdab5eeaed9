"""The hand-over law as a Drake system, between the blender and the robot."""

import numpy as np
from pydrake.systems.framework import LeafSystem

from pbp_drake.core.hand_over import check_limit, hand_over
from pbp_drake.systems.ports import PortGetters
from pbp_drake.systems.tick import checked_period, report_offset


class HandOverBase(PortGetters, LeafSystem):
    """What `HandOver` and `PoseHandOver` share: the `reference` input and the `command`
    output, the command their state (from `initial_command` on), set at each tick's report
    stage (why: `HandOver`) to the subclass's `_command(previous, reference)`."""

    def __init__(self, initial_command, control_period):
        super().__init__()
        self._period = checked_period(control_period)
        self._reference_port = self.DeclareVectorInputPort("reference", initial_command.size)
        self._state_index = index = self.DeclareDiscreteState(initial_command)
        self._command_port = self.DeclareStateOutputPort("command", index)
        self.DeclarePeriodicDiscreteUpdateEvent(
            self._period, report_offset(self._period), self._update)

    def _update(self, context, discrete_state):
        reference = self._reference_port.Eval(context)
        state = discrete_state.get_mutable_value(self._state_index)
        state[:] = self._command(state, reference)


class HandOver(HandOverBase):
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
    system's state, starting at `initial_position` at rest. It updates at the report stage
    of each tick, after the other systems have decided, so it reads the same tick's
    reference (docs/concepts/control-tick.md).
    """

    def __init__(self, initial_position, max_acceleration, max_speed, control_period):
        initial_position = np.asarray(initial_position, dtype=float).reshape(-1)
        if initial_position.size == 0 or not np.isfinite(initial_position).all():
            raise ValueError(f"initial_position must be finite, got {initial_position}")
        d = initial_position.size
        super().__init__(np.concatenate([initial_position, np.zeros(d)]), control_period)
        self._dimension = d
        self._max_acceleration = check_limit(max_acceleration, "max_acceleration", "m/s^2")
        self._max_speed = check_limit(max_speed, "max_speed", "m/s")

    def _command(self, previous, reference):
        d = self._dimension
        position, velocity = hand_over(previous[d:], reference[:d], reference[d:],
                                       self._max_acceleration, self._max_speed,
                                       self._period)
        return np.concatenate([position, velocity])
