"""A person with a gamepad in a Meshcat browser steering the hand in six DoF: the nearest
thing to the paper's 3-D mouse that a browser offers."""

import numpy as np

from pbp_drake.systems.operators.browser_input import (
    LEFT_SHOULDER, LEFT_STICK_X, LEFT_STICK_Y, LEFT_TRIGGER, RIGHT_SHOULDER, RIGHT_STICK_X,
    RIGHT_STICK_Y, RIGHT_TRIGGER, apply_dead_zone, check_params)
from pbp_drake.systems.operators.gamepad_operator import GamepadParams
from pbp_drake.systems.operators.pose_operator_base import PoseOperatorBase
from pbp_drake.systems.ports import OperatorTwist

_AXES, _BUTTONS = 4, 8  # the sticks' axes; the buttons up to RIGHT_TRIGGER
# A shoulder button counts as pressed above this value (they send 0 or 1).
PRESSED = 0.5


class PoseGamepadParams(GamepadParams):
    """`GamepadParams` of a person with a gamepad steering the hand in six DoF (`dead_zone`
    is each trigger's too)."""


class PoseGamepadOperator(PoseOperatorBase):
    """A world-frame twist from the gamepad Meshcat sees.

    .. pydrake_system::

        name: PoseGamepadOperator
        input_ports:
        - hand_state
        output_ports:
        - operator_twist
        - operator_active

    The left stick and the triggers translate, the right stick and the shoulders rotate
    the hand in its operator frame (`core.operator_frame`); the mapping:
    docs/concepts/six-dof.md, "Browser operators". The speeds, their caps and the forward
    drop of PBP modes are `PoseOperatorBase`'s. `operator_active` is 1 while the twist is
    not zero. With no gamepad the twist is zero and inactive. `exclusive` is as in
    `BrowserOperator`.
    """

    def __init__(self, meshcat, control_period, allow_forward,
                 params=PoseGamepadParams(), nominal_speed=None, exclusive=True):
        check_params(params, fraction=("dead_zone",))
        super().__init__(meshcat, control_period, allow_forward, params, nominal_speed,
                         exclusive)
        self._dead_zone = float(params.dead_zone)
        self._declare_gamepad(_AXES, _BUTTONS)
        self._declare_operator_outputs()

    def _update(self, context, discrete_state):
        values = self._read_gamepad(context, discrete_state)
        if values is None:
            self._store_sample(discrete_state, np.zeros(OperatorTwist.size), False)
            return
        twist = self._twist(context, *self._unit_inputs(*values))
        self._store_sample(discrete_state, twist, bool(np.any(twist != 0.0)))

    def _unit_inputs(self, axes, buttons):
        """`(forward, left, up)`, `(yaw, pitch, roll)` in [-1, 1] from the controls."""
        dead_zone = self._dead_zone
        # Browser axes: x right, y down.
        forward, left = apply_dead_zone([-axes[LEFT_STICK_Y], -axes[LEFT_STICK_X]], dead_zone)
        up = (apply_dead_zone([buttons[RIGHT_TRIGGER]], dead_zone)[0]
              - apply_dead_zone([buttons[LEFT_TRIGGER]], dead_zone)[0])
        yaw, pitch = apply_dead_zone([-axes[RIGHT_STICK_X], -axes[RIGHT_STICK_Y]], dead_zone)
        roll = (float(buttons[RIGHT_SHOULDER] > PRESSED)
                - float(buttons[LEFT_SHOULDER] > PRESSED))
        return np.array([forward, left, up]), np.array([yaw, pitch, roll])
