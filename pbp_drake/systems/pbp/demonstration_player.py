"""An open-loop, time-indexed policy P: the demonstration played back (explicit arbitration)."""

import numpy as np
from pydrake.systems.framework import LeafSystem

from pbp_drake.core.dmp import validate_demonstration
from pbp_drake.systems.ports import PortGetters
from pbp_drake.systems.tick import checked_period


class DemonstrationPlayer(PortGetters, LeafSystem):
    """Outputs the demonstration's next state at every control tick, whatever the robot does.

    .. pydrake_system::

        name: DemonstrationPlayer
        output_ports:
        - references

    At tick `t_k` it holds the demonstration at `t_k + control_period` (linearly
    interpolated, the last sample held after the end) as `references` of one goal:
    `[position (D), velocity (D)]`, the same layout as `DmpBank` with K = 1.
    """

    def __init__(self, times, positions, control_period):
        super().__init__()
        times, positions = validate_demonstration(times, positions)
        self._times = times - times[0]
        self._positions = positions
        self._velocities = np.gradient(positions, self._times, axis=0)
        self._velocities[-1] = 0.0
        self._period = checked_period(control_period)
        index = self.DeclareDiscreteState(self._sample(self._period))
        self._references_port = self.DeclareStateOutputPort("references", index)
        self.DeclarePeriodicDiscreteUpdateEvent(self._period, 0.0, self._update)

    def _sample(self, time):
        position = [np.interp(time, self._times, column) for column in self._positions.T]
        velocity = [np.interp(time, self._times, column, right=0.0)
                    for column in self._velocities.T]
        return np.concatenate([position, velocity])

    def _update(self, context, discrete_state):
        discrete_state.get_mutable_vector().set_value(
            self._sample(context.get_time() + self._period))
