"""One DMP, stepped with a plain per-dimension loop: the readable reference.

`Dmp` keeps a state of its own (`phase`, `position`, `scaled_velocity`) and a stateful API
(`reset`, `next_step`, `rollout`), as NumPy users expect of one movement primitive: no Drake
system holds one, and it is the oracle the vectorised, immutable `DmpBankModel` is tested
against. `SingleDmp` is what it shares with `OrientationDmp`.
"""

import dataclasses

import numpy as np

from pbp_drake.core.dmp._checks import as_point, dmp_settings, positive
from pbp_drake.core.dmp.fitting import fit_weights, minimum_jerk, validate_demonstration
from pbp_drake.core.dmp.settings import DmpSettings, phase_decay, step_matrices


def straight_weights(settings, duration, span):
    """Weights `(N, D)` of a minimum-jerk straight path, `span` (D,) its goal minus start.

    Fitted on a unit reach so that a dimension with `g = y0` still gets the straight-path
    shape; the Ijspeert `(g - y0)` factor then scales it to any goal, the Pastor form takes
    `span` here."""
    times, unit = minimum_jerk(np.zeros(1), np.ones(1), positive(duration, "duration"))
    unit_weights, _ = fit_weights(times, unit, settings)
    return unit_weights * (span if settings.formulation == "pastor" else np.ones(span.size))


class SingleDmp:
    """What `Dmp` and `OrientationDmp` share: the model (settings, weights `(N, D)`, start,
    goal, duration, amplitude scaling), the phase, the first-order-hold step of a state
    `(D,)`, `straight` and `rollout`. A subclass gives `_ends` (its start and goal checked),
    `_span` (goal minus start, `(D,)`), `attractor` and `next_step`, and names in `PATH`
    the state `rollout` samples."""

    def __init__(self, weights, start, goal, duration, settings, amplitude_scaling,
                 dimension):
        # A private copy (validated again): the caller's settings, or the shared default
        # instance, may be changed later, and the basis below is computed once.
        self._settings = dataclasses.replace(dmp_settings(settings))
        self.start, self.goal = self._ends(start, goal)
        self.weights = np.asarray(weights, dtype=float).reshape(self._settings.basis_count, -1)
        if self.weights.shape[1] != dimension:
            raise ValueError(f"weights have {self.weights.shape[1]} dimensions, expected "
                             f"{dimension}")
        if not np.isfinite(self.weights).all():
            raise ValueError("weights contain NaN or infinite values")
        self.duration = positive(duration, "duration")
        self.amplitude_scaling = (
            np.ones(dimension, bool)
            if amplitude_scaling is None
            else np.asarray(amplitude_scaling, bool).reshape(dimension)
        )
        self._centres, self._widths = self._settings.basis()
        self.reset()

    @property
    def settings(self):
        """The DMP's gains and basis (a copy: changing it does not change the DMP)."""
        return dataclasses.replace(self._settings)

    @classmethod
    def straight(cls, start, goal, duration, settings=DmpSettings(), profile="minimum_jerk"):
        """A DMP with no demonstration: a straight path from `start` to `goal`.

        `profile="minimum_jerk"` fits a minimum-jerk reach (bell-shaped speed, done at
        `duration`); `profile="zero_forcing"` uses `f = 0` (straight too, from rest, but with
        the abrupt start of a critically damped spring).
        """
        start, goal = cls._ends(start, goal)
        span = cls._span(start, goal)
        dmp_settings(settings)
        if profile == "zero_forcing":
            weights = np.zeros((settings.basis_count, span.size))
            return cls(weights, start, goal, duration, settings)
        if profile != "minimum_jerk":
            raise ValueError(
                f"profile {profile!r} is unknown; use 'minimum_jerk' or 'zero_forcing'")
        return cls(straight_weights(settings, duration, span), start, goal, duration,
                   settings)

    def _shape(self, phase):
        """The forcing term's shape `(psi . w / sum psi) x` at `phase`, `(D,)`."""
        psi = np.exp(-self._widths * (phase - self._centres) ** 2)
        return (psi @ self.weights) / psi.sum() * phase

    def _free_step(self, values, z, dt, goal):
        """One first-order-hold step of the state `(values, z)` (D,) toward the attractor
        at `goal`; advances the phase and returns the new `(values, z)`, new arrays."""
        phi, gamma = step_matrices(self._settings.stiffness, self._settings.damping,
                                   self.duration, dt)
        decay = phase_decay(self._settings, self.duration, dt)
        # The attractor moves linearly in time from its value at this step's phase to its
        # value at the next (first-order hold).
        start = self.attractor(self.phase, goal)
        end = self.attractor(self.phase * decay, goal)
        new_values, new_z = np.empty(values.size), np.empty(values.size)
        for dim in range(values.size):
            offset = values[dim] - start[dim]
            rate = (end[dim] - start[dim]) / dt
            new_values[dim] = (end[dim] + phi[0, 0] * offset + phi[0, 1] * z[dim]
                               - gamma[0, 0] * rate)
            new_z[dim] = phi[1, 0] * offset + phi[1, 1] * z[dim] - gamma[1, 0] * rate
        self.phase *= decay
        return new_values, new_z

    def rollout(self, dt, duration=None):
        """Open-loop path `(steps + 1, ...)` of the state `PATH` from the current state, the
        state kept."""
        dt = positive(dt, "dt")
        duration = self.duration if duration is None else positive(duration, "duration")
        saved = dict(vars(self))  # a step replaces the state's arrays, never writes in them
        steps = int(round(duration / dt))
        path = [getattr(self, self.PATH)]
        for _ in range(steps):
            path.append(self.next_step(dt)[0])
        vars(self).update(saved)
        return np.array(path)


class Dmp(SingleDmp):
    """One DMP in D dimensions, stepped with a plain per-dimension loop (`straight` and
    `rollout`: `SingleDmp`'s)."""

    PATH = "position"

    def __init__(self, weights, start, goal, duration, settings=DmpSettings(),
                 amplitude_scaling=None):
        super().__init__(weights, start, goal, duration, settings, amplitude_scaling,
                         np.size(start))

    @staticmethod
    def _ends(start, goal):
        start = as_point(start, "start")
        return start, as_point(goal, "goal", dimension=start.size)

    @staticmethod
    def _span(start, goal):
        return goal - start

    @classmethod
    def from_demonstration(cls, times, positions, settings=DmpSettings()):
        """Learns the DMP of ONE demonstration; start, goal and duration are the demo's."""
        times, positions = validate_demonstration(times, positions)
        weights, scaling = fit_weights(times, positions, settings)
        return cls(weights, positions[0], positions[-1], times[-1] - times[0], settings, scaling)

    def reset(self, position=None, scaled_velocity=None):
        """Phase to 1, position to `start` (or `position`), scaled velocity to 0 (or given)."""
        self.phase = 1.0
        size = self.start.size
        self.position = (self.start.copy() if position is None
                         else as_point(position, "position", dimension=size))
        self.scaled_velocity = (
            np.zeros(size) if scaled_velocity is None
            else as_point(scaled_velocity, "scaled_velocity", dimension=size)
        )

    def attractor(self, phase, goal):
        """The moving attractor `y_attr(x, g)` per dimension (docs/concepts/dmp.md, "The two
        formulations")."""
        shape = self._shape(phase)
        result = np.empty(self.start.size)
        for dim in range(self.start.size):
            if self._settings.formulation == "ijspeert":
                amplitude = goal[dim] - self.start[dim] if self.amplitude_scaling[dim] else 1.0
                result[dim] = goal[dim] + shape[dim] * amplitude / self._settings.stiffness
            else:
                result[dim] = goal[dim] - (goal[dim] - self.start[dim]) * phase + shape[dim]
        return result

    def next_step(self, dt, goal=None, robot_position=None, robot_velocity=None,
                  phase_locked=False):
        """Advances one control step from the robot's state; returns (position, velocity).

        `robot_position` replaces the DMP's position (PBP's re-integration from the robot);
        while `phase_locked`, the DMP does not advance: its velocity follows `robot_velocity`
        and it returns the robot's state.
        """
        positive(dt, "dt")
        goal = self.goal if goal is None else as_point(goal, "goal", dimension=self.start.size)
        if robot_position is not None:
            self.position = as_point(robot_position, "robot_position", dimension=self.start.size)
        tau = self.duration
        if phase_locked:
            if robot_velocity is not None:
                self.scaled_velocity = tau * as_point(robot_velocity, "robot_velocity",
                                                      dimension=self.start.size)
            return self.position.copy(), self.scaled_velocity / tau
        self.position, self.scaled_velocity = self._free_step(
            self.position, self.scaled_velocity, dt, goal)
        return self.position.copy(), self.scaled_velocity / tau
