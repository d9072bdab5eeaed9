"""A person at the keyboard of a Meshcat browser steering the hand in six DoF: arrows and
PageUp/PageDown translate, or after the mode key R rotate."""

import numpy as np

from pbp_drake.systems.operators.browser_input import check_params
from pbp_drake.systems.operators.keyboard_operator import KeyboardParams
from pbp_drake.systems.operators.pose_operator_base import PoseOperatorBase

# Each button's label names what its key does in both modes: translate | rotate.
FORWARD_KEY = "↑ forward | pitch down"
BACK_KEY = "↓ back | pitch up"
LEFT_KEY = "← left | yaw left"
RIGHT_KEY = "→ right | yaw right"
UP_KEY = "PageUp: up | roll right"
DOWN_KEY = "PageDown: down | roll left"

#: Button name -> JavaScript `KeyboardEvent.code` that clicks it.
KEY_BUTTONS = {
    FORWARD_KEY: "ArrowUp",
    BACK_KEY: "ArrowDown",
    LEFT_KEY: "ArrowLeft",
    RIGHT_KEY: "ArrowRight",
    UP_KEY: "PageUp",
    DOWN_KEY: "PageDown",
}
# What one held key adds: (forward, left, up) when translating, (pitch, yaw, roll) when
# rotating (the same keys: ↑ tips the approach axis down as a pushed stick does).
_KEY_AXES = {
    FORWARD_KEY: (1.0, 0.0, 0.0),
    BACK_KEY: (-1.0, 0.0, 0.0),
    LEFT_KEY: (0.0, 1.0, 0.0),
    RIGHT_KEY: (0.0, -1.0, 0.0),
    UP_KEY: (0.0, 0.0, 1.0),
    DOWN_KEY: (0.0, 0.0, -1.0),
}
TRANSLATE, ROTATE = 0, 1
MODE_KEY = "KeyR"
#: The mode button's label in each mode: the page shows the mode this way.
MODE_LABELS = ("Mode: translate (R: rotate)", "Mode: rotate (R: translate)")


class PoseKeyboardParams(KeyboardParams):
    """`KeyboardParams` of a person at the keyboard steering the hand in six DoF."""


class PoseKeyboardOperator(PoseOperatorBase):
    """A world-frame twist from Meshcat buttons bound to keys, in two modes.

    .. pydrake_system::

        name: PoseKeyboardOperator
        input_ports:
        - hand_state
        output_ports:
        - operator_twist
        - operator_active

    The arrows and PageUp/PageDown translate the hand in its operator frame
    (`core.operator_frame`), or rotate it after R; the mapping: docs/concepts/six-dof.md,
    "Browser operators". The mode button's label (`MODE_LABELS`) shows the mode; the run
    starts translating. A held R toggles once. Held keys combine into one direction; the
    speeds and the forward drop of PBP modes are `PoseOperatorBase`'s. `operator_active` is
    1 while a key is held whose own motion is not wholly dropped. Keys are held as in
    `KeyboardOperator`; `exclusive` is as in `BrowserOperator`; `Delete()` removes the
    buttons.
    """

    def __init__(self, meshcat, control_period, allow_forward,
                 params=PoseKeyboardParams(), nominal_speed=None, exclusive=True):
        check_params(params, positive=("hold_time",))
        super().__init__(meshcat, control_period, allow_forward, params, nominal_speed,
                         exclusive)
        self._declare_keys(KEY_BUTTONS, _KEY_AXES, params.hold_time)
        self._shown = MODE_LABELS[TRANSLATE]
        meshcat.AddButton(self._shown, MODE_KEY)
        # [mode, the mode button's click count last seen, the time of its last click].
        self._mode_index = self.DeclareDiscreteState([TRANSLATE, 0.0, -np.inf])
        self._declare_operator_outputs()

    def button_names(self):
        """The buttons this operator shows: the keys', then the mode's."""
        return [*self._keys.names, self._shown]

    def mode(self, context):
        """`TRANSLATE` or `ROTATE` in this operator's `context`."""
        return int(context.get_discrete_state(self._mode_index).value()[0])

    def Delete(self):
        """Removes this operator's buttons from Meshcat (they stay there otherwise)."""
        self._keys.delete()
        self._meshcat.DeleteButton(self._shown, strict=False)

    def _show(self, mode):
        """Relabels the mode button; returns its click count (a new button's is 0)."""
        label = MODE_LABELS[mode]
        if label != self._shown:
            self._meshcat.DeleteButton(self._shown, strict=False)
            self._meshcat.AddButton(label, MODE_KEY)
            self._shown = label
        return self._meshcat.GetButtonClicks(label)

    def _snapshot(self, context, discrete_state):
        super()._snapshot(context, discrete_state)
        discrete_state.get_mutable_vector(self._mode_index).set_value(
            [TRANSLATE, self._show(TRANSLATE), -np.inf])

    def _update(self, context, discrete_state):
        # R is read with the keys, before the connections are counted.
        clicks = self._keys.clicks()
        mode, seen, last = context.get_discrete_state(self._mode_index).value()
        mode = int(mode)
        mode_clicks = self._show(mode)
        time = context.get_time()
        keys, paused = self._step_keys(context, discrete_state, clicks)
        if paused:
            seen, last = self._show(mode), -np.inf
        else:
            toggled = mode_clicks > seen and time - last >= self._keys.hold_time - 1e-9
            if mode_clicks > seen:  # a click within hold_time of the last is R's repeat
                last = time
            seen = mode_clicks
            if toggled:
                mode = 1 - mode
                seen = self._show(mode)  # the relabelled button counts from 0
        discrete_state.get_mutable_vector(self._mode_index).set_value([mode, seen, last])
        self._store_sample(discrete_state, *self._command(context, keys, mode))

    def _command(self, context, keys, mode):
        held = self._keys.held(keys, context.get_time())
        if not held.any():
            return np.zeros(6), False
        effective = any(np.any(self._key_twist(context, row, mode) != 0.0)
                        for row in self._axes[held])
        return self._key_twist(context, self._axes[held].sum(axis=0), mode), effective

    def _key_twist(self, context, keys, mode):
        if mode == TRANSLATE:
            return self._twist(context, keys, np.zeros(3))
        pitch, yaw, roll = keys
        return self._twist(context, np.zeros(3), np.array([yaw, pitch, roll]))
