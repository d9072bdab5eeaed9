"""A zero-order hold that starts from a given value."""

import numpy as np
from pydrake.systems.framework import LeafSystem

from pbp_drake.systems.ports import PortGetters
from pbp_drake.systems.tick import SENSE_OFFSET, checked_period


class SampleHold(PortGetters, LeafSystem):
    """Samples its input at each control tick and holds it; starts at `initial_value`.

    .. pydrake_system::

        name: SampleHold
        input_ports:
        - u
        output_ports:
        - y

    Unlike Drake's ZeroOrderHold (which starts at zero, the robot at the world's origin),
    it starts where the robot does. It samples at the sense stage of each tick.
    """

    def __init__(self, period, initial_value):
        super().__init__()
        initial_value = np.asarray(initial_value, dtype=float)
        if initial_value.ndim != 1 or initial_value.size == 0:
            raise ValueError(f"initial_value must be a non-empty vector, got "
                             f"{initial_value.tolist()}")
        self._input_port = self.DeclareVectorInputPort("u", initial_value.size)
        index = self.DeclareDiscreteState(initial_value)
        self.DeclareStateOutputPort("y", index)
        self.DeclarePeriodicDiscreteUpdateEvent(checked_period(period, "period"), SENSE_OFFSET,
                                                self._update)

    def _update(self, context, discrete_state):
        discrete_state.get_mutable_vector().set_value(self._input_port.Eval(context))
