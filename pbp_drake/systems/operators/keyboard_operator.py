"""A person at the keyboard of a Meshcat browser: arrow keys move the end effector, Q/E turn it."""

import dataclasses

import numpy as np

from pbp_drake.core.reach_task import rotate_planar
from pbp_drake.systems.operators.browser_input import BrowserOperator
from pbp_drake.systems.ports import EeState, OperatorCommand

FORWARD_BUTTON = "Forward (↑)"
BACK_BUTTON = "Back (↓)"
LEFT_BUTTON = "Left (←)"
RIGHT_BUTTON = "Right (→)"
TURN_LEFT_BUTTON = "Turn left (Q)"
TURN_RIGHT_BUTTON = "Turn right (E)"
UP_BUTTON = "Up (R)"
DOWN_BUTTON = "Down (F)"

#: Button name -> JavaScript `KeyboardEvent.code` that clicks it.
KEY_BUTTONS = {
    FORWARD_BUTTON: "ArrowUp",
    BACK_BUTTON: "ArrowDown",
    LEFT_BUTTON: "ArrowLeft",
    RIGHT_BUTTON: "ArrowRight",
    TURN_LEFT_BUTTON: "KeyQ",
    TURN_RIGHT_BUTTON: "KeyE",
}

# What one held key adds to [forward, left, up, yaw] (robot frame, unit speeds); up and
# down only with `vertical=True`.
_KEY_AXES = {
    FORWARD_BUTTON: (1.0, 0.0, 0.0, 0.0),
    BACK_BUTTON: (-1.0, 0.0, 0.0, 0.0),
    LEFT_BUTTON: (0.0, 1.0, 0.0, 0.0),
    RIGHT_BUTTON: (0.0, -1.0, 0.0, 0.0),
    TURN_LEFT_BUTTON: (0.0, 0.0, 0.0, 1.0),
    TURN_RIGHT_BUTTON: (0.0, 0.0, 0.0, -1.0),
    UP_BUTTON: (0.0, 0.0, 1.0, 0.0),
    DOWN_BUTTON: (0.0, 0.0, -1.0, 0.0),
}

#: The buttons `vertical=True` adds (name -> `KeyboardEvent.code`): R up, F down.
VERTICAL_KEY_BUTTONS = {
    UP_BUTTON: "KeyR",
    DOWN_BUTTON: "KeyF",
}


@dataclasses.dataclass
class KeyboardParams:
    """A person at the browser's keyboard (HSR tasks): arrows move, Q and E turn."""

    #: The arrows' speed (m/s); 0 takes the task's nominal speed, that of its DMPs.
    speed: float = 0.0
    #: Q and E's turn rate (rad/s).
    rotation_speed: float = 0.6
    #: A key counts as held this long (s) after its last press. The browser repeats a held
    #: key, but only after the system's repeat delay (often 0.25..0.66 s): bridge it.
    hold_time: float = 0.6


class KeyboardOperator(BrowserOperator):
    """Task-space velocity commands from Meshcat buttons bound to keys.

    .. pydrake_system::

        name: KeyboardOperator
        input_ports:
        - ee_state
        output_ports:
        - operator_command
        - operator_active

    Adds one Meshcat button per key (`KEY_BUTTONS`): ↑/↓ forward/back along the end
    effector's heading (`ee_state`), ←/→ sideways, Q/E turn left/right. A click of a button
    (or a keydown of its key, repeats included) keeps the key held for `hold_time` seconds.
    Translation keys combine into one direction at `speed` (m/s); Q/E give a yaw rate of
    ±`rotation_speed` (rad/s). With `allow_forward=False` (PBP modes) the forward button is
    not added. With `vertical=True` two more buttons (`VERTICAL_KEY_BUTTONS`) move the hand
    up (R) and down (F), and the translation keys combine in 3-D.

    Output `operator_command` is `[vx, vy, vz, yaw_rate]` in the world frame (vz = 0
    unless `vertical`); `operator_active` is 1 while any effective key is held (even if
    opposite keys cancel). `exclusive` is as in `BrowserOperator`. The buttons stay in
    Meshcat until `Delete()`.
    """

    # The buttons' names, for code that presses them (`Meshcat`'s injected clicks, tests).
    FORWARD_BUTTON, BACK_BUTTON = FORWARD_BUTTON, BACK_BUTTON
    LEFT_BUTTON, RIGHT_BUTTON = LEFT_BUTTON, RIGHT_BUTTON
    TURN_LEFT_BUTTON, TURN_RIGHT_BUTTON = TURN_LEFT_BUTTON, TURN_RIGHT_BUTTON
    UP_BUTTON, DOWN_BUTTON = UP_BUTTON, DOWN_BUTTON

    def __init__(self, meshcat, control_period, allow_forward, params=KeyboardParams(),
                 nominal_speed=None, exclusive=True, vertical=False):
        super().__init__(meshcat, OperatorCommand.size, control_period, allow_forward, params,
                         nominal_speed, exclusive)
        keys = {name: code for name, code in KEY_BUTTONS.items()
                if allow_forward or name != FORWARD_BUTTON}
        if vertical:
            keys.update(VERTICAL_KEY_BUTTONS)
        self._declare_keys(keys, _KEY_AXES, params.hold_time)
        self._ee_state_port = self.DeclareVectorInputPort("ee_state", EeState.size)
        self._declare_operator_outputs()

    def button_names(self):
        """The names of the buttons this operator added to Meshcat."""
        return list(self._keys.names)

    def Delete(self):
        """Removes this operator's buttons from Meshcat (they stay there otherwise)."""
        self._keys.delete()

    def _update(self, context, discrete_state):
        keys, _ = self._step_keys(context, discrete_state, self._keys.clicks())
        self._store_sample(discrete_state, *self._command(context, keys))

    def _command(self, context, keys):
        held = self._keys.held(keys, context.get_time())
        forward, left, up, yaw = self._axes[held].sum(axis=0) if held.any() else np.zeros(4)
        # One direction at `speed`: e.g. ↑ with ← goes diagonally.
        local = np.array([forward, left, up])
        norm = np.linalg.norm(local)
        if norm > 0:
            local *= self._speed / norm
        velocity = rotate_planar(local[:2], EeState(self._ee_state_port.Eval(context)).heading)
        yaw_rate = self._rotation_speed * yaw
        return np.array([velocity[0], velocity[1], local[2], yaw_rate]), bool(held.any())
