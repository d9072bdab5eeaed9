"""What the browser operators share: buttons held for a while after each click (keys), and
gamepad sticks with a dead zone, read from Meshcat.

The keyboard operators keep their buttons' state as one vector in discrete state (`HeldButtons`
reads and steps it), so the system holds no state outside its Context. Meshcat must be used
only from the thread that created it.
"""

import numpy as np


class HeldButtons:
    """Meshcat buttons, each bound to a key, that count as held `hold_time` seconds after
    their last click (a browser re-clicks a held key at its repeat rate, after a delay).

    The state vector is `[last click counts (n), last click times (n)]`; `-inf` means never.
    """

    def __init__(self, meshcat, keys, hold_time):
        """`keys`: button name -> JavaScript `KeyboardEvent.code`, in order."""
        self._meshcat = meshcat
        self.names = list(keys)
        self._hold_time = float(hold_time)
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
        return time - state[len(self.names):] < self._hold_time - 1e-9


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
    entries 0, or None when there is no gamepad. The browser sends an empty status when the
    gamepad disconnects, and Meshcat then keeps the old index: empty axes mean none too.
    A value that is not finite (no real pad sends one) reads as a control at rest."""
    axes = list(gamepad.axes)
    if gamepad.index is None or len(axes) < 2:
        return None
    buttons = list(gamepad.button_values)
    axes = _padded(axes, axis_count)
    buttons = _padded(buttons, button_count)
    return axes, buttons


def _padded(values, count):
    sent = _as_sent(values, count)
    return np.where(np.isfinite(sent), sent, 0.0)


def raw_values(gamepad, axis_count, button_count=0):
    """The first `axis_count` axes then `button_count` button values of a Meshcat gamepad
    status as sent (missing ones NaN): what an operator compares to tell whether the
    controls moved since a pause."""
    return np.concatenate([_as_sent(gamepad.axes, axis_count),
                           _as_sent(gamepad.button_values, button_count)])


def _as_sent(values, count):
    values = list(values)[:count]
    return np.array(values + [np.nan] * (count - len(values)), float)


def fresh_after_pause(guard, meshcat, stale, gamepad, axis_count, button_count=0):
    """The gamepad operators' rule after a `BrowserGuard` pause: Meshcat keeps the last state
    it received from whichever page sent it, so the controls held when a pause ends are
    ignored until they change. `stale` is the `raw_values` remembered (all NaN: none);
    returns the new `stale` and whether `gamepad` (read before the guard) may be used."""
    if guard is not None and guard.wait_while_shared():
        stale = raw_values(meshcat.GetGamepad(), axis_count, button_count)
    elif not np.array_equal(raw_values(gamepad, axis_count, button_count), stale,
                            equal_nan=True):
        stale = np.full(len(stale), np.nan)  # the controls moved since: read them again
    return stale, bool(np.isnan(stale).all())
