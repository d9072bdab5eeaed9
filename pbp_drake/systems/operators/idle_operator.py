"""The absent operator (PBP-NoUser): always zero."""

import numpy as np

from pbp_drake.systems.operators.sampled_operator import SampledOperator


class IdleOperator(SampledOperator):
    """An operator that never acts: `u = 0`, `operator_active = 0`.

    .. pydrake_system::

        name: IdleOperator
        output_ports:
        - operator_command
        - operator_active
    """

    def __init__(self, dimension, control_period):
        super().__init__(dimension, control_period)
        self._declare_operator_outputs()

    def _sample(self, context):
        return np.zeros(self._dimension), False
