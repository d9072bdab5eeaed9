"""A person with a gamepad in a Meshcat browser: sticks move and turn the end effector."""

import dataclasses

import numpy as np

from pbp_drake.core.reach_task import rotate_planar
from pbp_drake.systems.operators.browser_input import (
    LEFT_STICK_X, LEFT_STICK_Y, RIGHT_STICK_X, BrowserOperator, apply_dead_zone, check_params)
from pbp_drake.systems.ports import EeState, OperatorCommand

_STICK_AXES = 3  # LEFT_STICK_X, LEFT_STICK_Y, RIGHT_STICK_X


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


class GamepadOperator(BrowserOperator):
    """Task-space velocity commands from the gamepad Meshcat sees.

    .. pydrake_system::

        name: GamepadOperator
        input_ports:
        - ee_state
        output_ports:
        - operator_command
        - operator_active

    Reads `meshcat.GetGamepad()` each control tick. The left stick moves the end effector
    along its heading (`ee_state`) at up to `speed` (m/s); the right stick's x turns it at
    up to `rotation_speed` (rad/s); each stick has a radial `dead_zone`. With
    `allow_forward=False` (PBP modes) the left stick's forward part is dropped. Output
    `operator_command` is `[vx, vy, 0, yaw_rate]` in the world frame; `operator_active` is
    1 while an effective stick is outside its dead zone. With no gamepad the command is
    zero and inactive. `exclusive` is as in `BrowserOperator`.
    """

    def __init__(self, meshcat, control_period, allow_forward, params=GamepadParams(),
                 nominal_speed=None, exclusive=True):
        check_params(params, fraction=("dead_zone",))
        super().__init__(meshcat, OperatorCommand.size, control_period, allow_forward, params,
                         nominal_speed, exclusive)
        self._dead_zone = float(params.dead_zone)
        self._ee_state_port = self.DeclareVectorInputPort("ee_state", EeState.size)
        self._declare_gamepad(_STICK_AXES)
        self._declare_operator_outputs()

    def _update(self, context, discrete_state):
        values = self._read_gamepad(context, discrete_state)
        if values is None:
            self._store_sample(discrete_state, np.zeros(OperatorCommand.size), False)
        else:
            self._store_sample(discrete_state, *self._command(context, values[0]))

    def _command(self, context, axes):
        # Browser axes: x right, y down. Robot frame: forward, left.
        stick = apply_dead_zone([-axes[LEFT_STICK_Y], -axes[LEFT_STICK_X]], self._dead_zone)
        turn = apply_dead_zone([-axes[RIGHT_STICK_X]], self._dead_zone)[0]
        if not self._allow_forward:
            stick[0] = min(stick[0], 0.0)
        active = bool(np.any(stick != 0) or turn != 0)
        heading = EeState(self._ee_state_port.Eval(context)).heading
        velocity = rotate_planar(self._speed * stick, heading)
        return np.array([velocity[0], velocity[1], 0.0, self._rotation_speed * turn]), active
