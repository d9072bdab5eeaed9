"""What the browser operators share: the base `BrowserOperator`, buttons held for a while
after each click (keys), and gamepad sticks with a dead zone, read from Meshcat."""

import dataclasses
import math

import numpy as np
from pydrake.geometry import Meshcat

from pbp_drake.systems.operators.browser_guard import BrowserGuard
from pbp_drake.systems.operators.sampled_operator import SampledOperator, operator_speed

# The W3C standard gamepad mapping (https://w3c.github.io/gamepad/#remapping): stick y is
# DOWN, triggers are analog buttons in [0, 1], shoulders digital ones.
LEFT_STICK_X, LEFT_STICK_Y, RIGHT_STICK_X, RIGHT_STICK_Y = 0, 1, 2, 3
LEFT_SHOULDER, RIGHT_SHOULDER, LEFT_TRIGGER, RIGHT_TRIGGER = 4, 5, 6, 7


def check_params(params, positive=(), fraction=()):
    """Raises ValueError naming the field of the dataclass `params` that is not finite and
    positive (`positive` fields) or not in [0, 1) (`fraction` fields)."""
    kind = type(params).__name__
    if not dataclasses.is_dataclass(params) or isinstance(params, type):
        raise ValueError(f"params must be the operator's parameters (e.g. KeyboardParams), "
                         f"got {kind}")
    for field in positive:
        value = getattr(params, field)
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise ValueError(f"{kind}.{field} must be finite and positive, not {value!r}")
    for field in fraction:
        value = getattr(params, field)
        if not (isinstance(value, (int, float)) and 0.0 <= value < 1.0):
            raise ValueError(f"{kind}.{field} must be in [0, 1), not {value!r}")


class BrowserOperator(SampledOperator):
    """A person in a Meshcat browser, at its keyboard or gamepad.

    `params` (a dataclass with `speed`, 0 taking `nominal_speed`, and `rotation_speed`) is
    copied to `self.params`. `allow_forward` is False in PBP modes, where forward motion
    comes from the DMP phase. With `exclusive` a `BrowserGuard` pauses the simulation while
    more than one browser is connected, dropping what they send. Subclasses read their keys
    (`_declare_keys`, `_step_keys`) or gamepad (`_declare_gamepad`, `_read_gamepad`) in
    `_update`. Use Meshcat only from the thread that created it.
    """

    def __init__(self, meshcat, dimension, control_period, allow_forward, params,
                 nominal_speed, exclusive, command_name="operator_command"):
        super().__init__(dimension, control_period, command_name)
        if not isinstance(meshcat, Meshcat):
            raise ValueError(f"meshcat must be a pydrake Meshcat (StartMeshcat()), got "
                             f"{type(meshcat).__name__}")
        check_params(params)
        self.params = dataclasses.replace(params)
        self._meshcat = meshcat
        self.browser_guard = BrowserGuard(meshcat) if exclusive else None
        self._allow_forward = bool(allow_forward)
        self._speed = operator_speed(params.speed, nominal_speed)
        self._rotation_speed = float(params.rotation_speed)
        self._keys_index = None  # the keys' state, once `_declare_keys` declared it
        self._stale_index = None  # the pad's ignored controls, once `_declare_gamepad` did

    def _declare_keys(self, keys, axes, hold_time):
        """Adds one button per key (`keys`: name -> `KeyboardEvent.code`), `self._axes` the
        rows of `axes` (name -> what the held key adds) in the buttons' order, and the keys'
        state as discrete state."""
        self._keys = HeldButtons(self._meshcat, keys, hold_time)
        self._axes = np.array([axes[name] for name in self._keys.names])
        self._keys_index = self.DeclareDiscreteState(
            self._keys.released(np.zeros(len(self._keys))))
        self.DeclareInitializationDiscreteUpdateEvent(self._snapshot)

    def _snapshot(self, context, discrete_state):
        discrete_state.get_mutable_vector(self._keys_index).set_value(self._keys.released())

    def forget_keys(self, root_context):
        """Counts the key presses so far as seen, none held, in `root_context` (as at the
        simulation's initialization): keys pressed before a run's Start do not drive it
        once it starts. Nothing without keys (a gamepad's sticks are read as they stand)."""
        if self._keys_index is not None:
            context = self.GetMyMutableContextFromRoot(root_context)
            self._snapshot(context, context.get_mutable_discrete_state())

    def forget_input(self, root_context):
        """Forgets in `root_context` what the browser sent so far, as after a pause: the
        keys as `forget_keys` does, and the gamepad's controls as they stand, ignored until
        they change (Meshcat keeps the last pad state of a page that has gone)."""
        self.forget_keys(root_context)
        if self._stale_index is not None:
            context = self.GetMyMutableContextFromRoot(root_context)
            context.get_mutable_discrete_state().get_mutable_vector(self._stale_index).set_value(
                raw_values(self._meshcat.GetGamepad(), *self._gamepad_counts))

    def _step_keys(self, context, discrete_state, clicks):
        """Stores and returns the keys' state after `clicks`, and whether the guard paused
        (then every key is released). `clicks` are read before the connections are counted."""
        paused = self.browser_guard is not None and self.browser_guard.wait_while_shared()
        if paused:
            keys = self._keys.released()
        else:
            keys = self._keys.step(context.get_discrete_state(self._keys_index).value(),
                                   clicks, context.get_time())
        discrete_state.get_mutable_vector(self._keys_index).set_value(keys)
        return keys, paused

    def _declare_gamepad(self, axis_count, button_count=0):
        """Reads the gamepad's first `axis_count` axes and `button_count` buttons."""
        self._gamepad_counts = (axis_count, button_count)
        # The controls Meshcat held when the last pause ended (NaN: none to ignore).
        self._stale_index = self.DeclareDiscreteState(
            np.full(axis_count + button_count, np.nan))

    def _read_gamepad(self, context, discrete_state):
        """The gamepad's `gamepad_values`, or None: the controls held when a guard pause ends
        (Meshcat keeps whichever page's last state) are ignored until they change."""
        gamepad = self._meshcat.GetGamepad()
        counts = self._gamepad_counts
        stale = context.get_discrete_state(self._stale_index).value()
        if self.browser_guard is not None and self.browser_guard.wait_while_shared():
            stale = raw_values(self._meshcat.GetGamepad(), *counts)
        elif not np.array_equal(raw_values(gamepad, *counts), stale, equal_nan=True):
            stale = np.full(len(stale), np.nan)  # the controls moved since: read them again
        discrete_state.get_mutable_vector(self._stale_index).set_value(stale)
        return gamepad_values(gamepad, *counts) if np.isnan(stale).all() else None


class HeldButtons:
    """Meshcat buttons, each bound to a key, that count as held `hold_time` seconds after
    their last click (a browser re-clicks a held key at its repeat rate, after a delay).

    The state vector is `[last click counts (n), last click times (n)]`; `-inf` means never.
    """

    def __init__(self, meshcat, keys, hold_time):
        """`keys`: button name -> JavaScript `KeyboardEvent.code`, in order."""
        self._meshcat = meshcat
        self.names = list(keys)
        self.hold_time = float(hold_time)
        for name, code in keys.items():
            meshcat.AddButton(name, code)

    def __len__(self):
        return len(self.names)

    def delete(self):
        for name in self.names:
            self._meshcat.DeleteButton(name, strict=False)

    def clicks(self):
        return np.array([self._meshcat.GetButtonClicks(name) for name in self.names], float)

    def released(self, clicks=None):
        """The state with the clicks so far seen and no key held."""
        clicks = self.clicks() if clicks is None else clicks
        return np.concatenate([clicks, np.full(len(self.names), -np.inf)])

    def step(self, state, clicks, time):
        """The state after reading `clicks` at `time`: a clicked key's time is now. A count
        that drops (the button was re-added elsewhere) resyncs without a click."""
        n = len(self.names)
        clicked = clicks > state[:n]
        return np.concatenate([clicks, np.where(clicked, time, state[n:])])

    def held(self, state, time):
        """Which keys are held at `time` (bool, n)."""
        return time - state[len(self.names):] < self.hold_time - 1e-9


def apply_dead_zone(stick, dead_zone):
    """A stick's deflection (any number of axes) zeroed within the radial `dead_zone` of the
    centre, then rescaled to rise continuously from 0 at its edge to 1 at full tilt."""
    stick = np.asarray(stick, float)
    magnitude = np.linalg.norm(stick)
    if magnitude <= dead_zone:
        return np.zeros_like(stick)
    scaled = (min(magnitude, 1.0) - dead_zone) / (1.0 - dead_zone)
    return stick * (scaled / magnitude)


def gamepad_values(gamepad, axis_count, button_count=0):
    """`(axes (axis_count,), buttons (button_count,))` of a Meshcat gamepad status, missing
    or not finite entries 0, or None when there is no gamepad (empty axes: a disconnected
    one, whose index Meshcat keeps)."""
    if gamepad.index is None or len(gamepad.axes) < 2:
        return None
    return _padded(gamepad.axes, axis_count), _padded(gamepad.button_values, button_count)


def _padded(values, count):
    sent = _as_sent(values, count)
    return np.where(np.isfinite(sent), sent, 0.0)


def raw_values(gamepad, axis_count, button_count=0):
    """The first `axis_count` axes then `button_count` button values of a Meshcat gamepad
    status as sent (missing ones NaN)."""
    return np.concatenate([_as_sent(gamepad.axes, axis_count),
                           _as_sent(gamepad.button_values, button_count)])


def _as_sent(values, count):
    values = list(values)[:count]
    return np.array(values + [np.nan] * (count - len(values)), float)
