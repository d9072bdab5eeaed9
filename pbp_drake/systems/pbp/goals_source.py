"""The candidate goals as a source whose output changes only when the goals do."""

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem, NumericParameterIndex

from pbp_drake.core.coordinates import check_positions
from pbp_drake.systems.ports import PortGetters


class GoalsSource(PortGetters, LeafSystem):
    """Outputs K goals `(K, D)` flattened row-major, kept in a numeric parameter.

    .. pydrake_system::

        name: GoalsSource
        output_ports:
        - goals

    Unlike Drake's ConstantVectorSource, its output depends on the parameter alone, so its
    readers are not recomputed at every step. `set_goals` changes it in a context.
    """

    def __init__(self, goals):
        super().__init__()
        goals = np.asarray(goals, dtype=float)
        if goals.ndim != 2 or goals.size == 0:
            raise ValueError(f"goals must be a non-empty (K, D) array, got shape {goals.shape}")
        check_positions(goals, "goal")
        self._shape = goals.shape
        self._index = self.DeclareNumericParameter(BasicVector(goals.reshape(-1)))
        self._goals_port = self.DeclareVectorOutputPort(
            "goals", goals.size,
            lambda context, output: output.SetFrom(context.get_numeric_parameter(self._index)),
            prerequisites_of_calc={self.numeric_parameter_ticket(NumericParameterIndex(self._index))})

    def set_goals(self, context, goals):
        """Sets the goals `(K, D)` (the same K and D, finite and within
        `pbp_drake.core.coordinates`' bounds) in `context`."""
        goals = np.asarray(goals, dtype=float)
        if goals.shape != self._shape:
            raise ValueError(f"goals has shape {goals.shape}, the source holds {self._shape}")
        check_positions(goals, "goal")
        context.get_mutable_numeric_parameter(self._index).SetFromVector(goals.reshape(-1))
