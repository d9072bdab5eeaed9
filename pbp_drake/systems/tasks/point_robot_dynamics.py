"""The 2-D (any-D) robot of the paper's toy experiments as a Drake system."""

import dataclasses

import numpy as np
from pydrake.systems.framework import LeafSystem

from pbp_drake.core.point_robot import MassSpringDamper
from pbp_drake.systems.ports import PortGetters


@dataclasses.dataclass
class PointRobotParams:
    """The point robot's dynamics (`robot: {...}` in a scenario file)."""

    #: The point's mass (kg).
    mass: float = 1.0
    #: The tracking spring (N/m).
    stiffness: float = 400.0
    #: The tracking damper (N s/m).
    damping: float = 40.0
    #: The discrete time step (s).
    time_step: float = 0.001


class PointRobotDynamics(PortGetters, LeafSystem):
    """A point mass-spring-damper tracking a commanded position and velocity.

    .. pydrake_system::

        name: PointRobotDynamics
        input_ports:
        - command
        output_ports:
        - state

    `command` is `[reference position (D), reference velocity (D)]`; `state` is
    `[position (D), velocity (D)]`. The plant steps every `time_step` with an offset of half a
    step, so a controller that samples it at the control ticks (multiples of `time_step`)
    sees a settled state and its command applies from the very next plant step.
    """

    def __init__(self, initial_position, params=PointRobotParams()):
        super().__init__()
        initial_position = np.asarray(initial_position, dtype=float)
        if (initial_position.ndim != 1 or initial_position.size == 0
                or not np.isfinite(initial_position).all()):
            raise ValueError(f"initial_position must be a non-empty finite vector, got "
                             f"{initial_position.tolist()}")
        if not isinstance(params, PointRobotParams):
            raise ValueError(f"params must be PointRobotParams, got {type(params).__name__}")
        self._dimension = initial_position.size
        self.params = dataclasses.replace(params)
        time_step = params.time_step
        self._dynamics = MassSpringDamper(params.mass, params.stiffness, params.damping,
                                          time_step)
        self._command_port = self.DeclareVectorInputPort("command", 2 * self._dimension)
        state_index = self.DeclareDiscreteState(
            np.concatenate([initial_position, np.zeros(self._dimension)]))
        self.DeclareStateOutputPort("state", state_index)
        self.DeclarePeriodicDiscreteUpdateEvent(time_step, time_step / 2, self._step)

    def _step(self, context, discrete_state):
        d = self._dimension
        state = context.get_discrete_state_vector().value()
        command = self._command_port.Eval(context)
        position, velocity = self._dynamics.step(state[:d], state[d:], command[:d], command[d:])
        discrete_state.get_mutable_vector().set_value(np.concatenate([position, velocity]))
