"""The paper's virtual human for the 2-D toy scenes (Eq. 5)."""

import dataclasses

import numpy as np

from pbp_drake.core.toy_scene import repulsion_command
from pbp_drake.systems.operators.sampled_operator import SampledOperator


@dataclasses.dataclass
class ObstacleRepulsionParams:
    """The paper's virtual human: `speed` away from the nearest obstacle when closer than
    `distance_threshold`; along `axis` only when one is given (empty: radially)."""

    #: It pushes when the robot is closer than this (m) to the nearest obstacle.
    distance_threshold: float = 0.2
    #: How fast it pushes away (the command's unit, m/s; not negative).
    speed: float = 1.0
    #: The direction it pushes along (a vector); empty: radially from the obstacle.
    axis: list[float] = dataclasses.field(default_factory=list)


class ObstacleRepulsionOperator(SampledOperator):
    """Pushes the robot away from the nearest obstacle when it comes within a distance.

    .. pydrake_system::

        name: ObstacleRepulsionOperator
        input_ports:
        - robot_state
        output_ports:
        - operator_command
        - operator_active

    `params` are `ObstacleRepulsionParams`; with `axis` the push's sign is away from the
    obstacle (the paper's `sign(.) * 1`). Obstacles are `(centres (M, D), radii (M,))`.
    """

    def __init__(self, centres, radii, dimension, control_period,
                 params=ObstacleRepulsionParams()):
        super().__init__(dimension, control_period)
        self.params = dataclasses.replace(params)
        self._centres = np.asarray(centres, dtype=float).reshape(-1, dimension)
        self._radii = np.asarray(radii, dtype=float).reshape(-1)
        if not np.isfinite(self._centres).all():
            raise ValueError(f"centres must be finite, got {self._centres.tolist()}")
        if self._radii.shape != (len(self._centres),) or not (self._radii > 0).all():
            raise ValueError(f"radii must be one positive radius per centre "
                             f"({len(self._centres)}), got {self._radii.tolist()}")
        self._threshold = float(params.distance_threshold)
        self._speed = float(params.speed)
        self._axis = np.asarray(params.axis, dtype=float) if len(params.axis) else None
        self._robot_state_port = self.DeclareVectorInputPort("robot_state", 2 * dimension)
        self._declare_operator_outputs()

    def _sample(self, context):
        position = self._robot_state_port.Eval(context)[:self._dimension]
        return repulsion_command(position, self._centres, self._radii, self._threshold,
                                 self._speed, self._axis)
