"""The paper's virtual human for the 2-D toy scenes (Eq. 5)."""

import dataclasses
import math

import numpy as np

from pbp_drake.core.coordinates import is_real
from pbp_drake.core.toy_scene import repulsion_command
from pbp_drake.systems.operators.sampled_operator import SampledOperator
from pbp_drake.systems.ports import finite_fields


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
        dimension = self._dimension
        if not isinstance(params, ObstacleRepulsionParams):
            raise ValueError(f"params must be ObstacleRepulsionParams, got "
                             f"{type(params).__name__}")
        check_repulsion_params(params, dimension)
        self.params = dataclasses.replace(params)
        centres = np.asarray(centres, dtype=float)
        if centres.size and (centres.ndim != 2 or centres.shape[1] != dimension):
            raise ValueError(f"centres must be (M, {dimension}), an obstacle's centre a row, "
                             f"got shape {centres.shape}")
        self._centres = centres.reshape(-1, dimension)
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
        self._position_fields = [f"position[{i}]" for i in range(dimension)]
        self._declare_operator_outputs()

    def _sample(self, context):
        # A NaN position is farther from no obstacle than the threshold: it would push.
        position = finite_fields(self._robot_state_port.Eval(context)[:self._dimension],
                                 "robot_state", self._position_fields)
        return repulsion_command(position, self._centres, self._radii, self._threshold,
                                 self._speed, self._axis)


def check_repulsion_params(params, dimension, field="params"):
    """Raises ValueError naming the field of `params` (`ObstacleRepulsionParams`, called
    `field`) that the push cannot use: a NaN threshold pushed at any distance, a 0 one
    never, and a negative speed toward the obstacle."""
    threshold, speed = params.distance_threshold, params.speed
    if not (is_real(threshold) and math.isfinite(threshold) and threshold > 0):
        raise ValueError(f"{field}.distance_threshold must be finite and positive, got "
                         f"{threshold!r}")
    if not (is_real(speed) and math.isfinite(speed) and speed >= 0):
        raise ValueError(f"{field}.speed must be finite and not negative, got {speed!r}")
    axis = np.asarray(params.axis, dtype=float)
    if axis.size and (axis.shape != (dimension,) or not np.linalg.norm(axis) >= 1e-6):
        raise ValueError(f"{field}.axis must be empty (radially) or a direction of dimension "
                         f"{dimension} and length at least 1e-6, got {list(params.axis)}")
