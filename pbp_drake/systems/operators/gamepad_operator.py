"""A person with a gamepad in a Meshcat browser: sticks move and turn the end effector."""

import dataclasses

import numpy as np

from pbp_drake.core.reach_task import rotate_planar
from pbp_drake.systems.operators.browser_guard import BrowserGuard
from pbp_drake.systems.operators.browser_input import (
    apply_dead_zone, fresh_after_pause, gamepad_values)
from pbp_drake.systems.ports import EeState, OperatorCommand
from pbp_drake.systems.operators.sampled_operator import SampledOperator, operator_speed

# Standard gamepad mapping (https://w3c.github.io/gamepad/#remapping): stick y is DOWN.
LEFT_STICK_X, LEFT_STICK_Y, RIGHT_STICK_X = 0, 1, 2
_STICK_AXES = 3


@dataclasses.dataclass
class GamepadParams:
    """A person with a gamepad in the browser (HSR tasks): the left stick moves, the right
    stick turns."""

    #: The left stick's top speed (m/s); 0 takes the task's nominal speed, that of its DMPs.
    speed: float = 0.0
    #: The right stick's top turn rate (rad/s).
    rotation_speed: float = 0.6
    #: Each stick's radial dead zone, in [0, 1).
    dead_zone: float = 0.15


class GamepadOperator(SampledOperator):
    """Task-space velocity commands from the gamepad Meshcat sees.

    .. pydrake_system::

        name: GamepadOperator
        input_ports:
        - ee_state
        output_ports:
        - operator_command
        - operator_active

    Reads `meshcat.GetGamepad()` each control tick. The left stick moves the end effector
    in the robot frame (up = forward along the heading, left = heading + 90 deg) at up to
    `speed` (m/s); the right stick's x turns it (left = positive yaw rate) at up to
    `rotation_speed` (rad/s). Each stick has a radial dead zone of `dead_zone`, past which
    its deflection rises continuously from 0. With `allow_forward=False` (PBP modes) the
    forward part of the left stick is dropped; back still works.

    Input `ee_state` gives the heading. Output `operator_command` is `[vx, vy, vz,
    yaw_rate]` in the world frame (vz = 0); `operator_active` is 1 while a stick is outside
    its dead zone (a stick pushed only forward does not count when forward is not
    allowed). With no gamepad (none received, or reported disconnected) the command is
    zero and inactive. `exclusive` is `KeyboardOperator`'s; after a pause the gamepad
    state Meshcat last received (from whichever page) is ignored until the sticks report
    something new. Use Meshcat only from the thread that created it.
    """

    def __init__(self, meshcat, control_period, allow_forward, params=GamepadParams(),
                 nominal_speed=None, exclusive=True):
        if not 0.0 <= params.dead_zone < 1.0:
            raise ValueError(f"dead_zone must be in [0, 1), not {params.dead_zone}")
        super().__init__(OperatorCommand.size, control_period)
        self.params = dataclasses.replace(params)
        self._meshcat = meshcat
        self.browser_guard = BrowserGuard(meshcat) if exclusive else None
        self._allow_forward = bool(allow_forward)
        self._speed = operator_speed(params.speed, nominal_speed)
        self._rotation_speed = float(params.rotation_speed)
        self._dead_zone = float(params.dead_zone)
        self._ee_state_port = self.DeclareVectorInputPort("ee_state", EeState.size)
        # The stick axes Meshcat held when the last pause ended (NaN: none to ignore).
        self._stale_index = self.DeclareDiscreteState(np.full(_STICK_AXES, np.nan))
        self._declare_operator_outputs()

    def _update(self, context, discrete_state):
        # Read before the connections are counted (see KeyboardOperator._update).
        gamepad = self._meshcat.GetGamepad()
        stale, fresh = fresh_after_pause(
            self.browser_guard, self._meshcat,
            context.get_discrete_state(self._stale_index).value(), gamepad, _STICK_AXES)
        discrete_state.get_mutable_vector(self._stale_index).set_value(stale)
        if fresh:
            self._store_sample(discrete_state, *self._command(context, gamepad))
        else:
            self._store_sample(discrete_state, np.zeros(OperatorCommand.size), False)

    def _command(self, context, gamepad):
        values = gamepad_values(gamepad, _STICK_AXES)
        if values is None:
            return np.zeros(4), False
        axes = values[0]
        # Browser axes: x right, y down. Robot frame: forward, left.
        stick = apply_dead_zone([-axes[LEFT_STICK_Y], -axes[LEFT_STICK_X]], self._dead_zone)
        turn = apply_dead_zone([-axes[RIGHT_STICK_X]], self._dead_zone)[0]
        if not self._allow_forward:
            stick[0] = min(stick[0], 0.0)
        active = bool(np.any(stick != 0) or turn != 0)
        heading = EeState(self._ee_state_port.Eval(context)).heading
        velocity = rotate_planar(self._speed * stick, heading)
        return np.array([velocity[0], velocity[1], 0.0, self._rotation_speed * turn]), active
