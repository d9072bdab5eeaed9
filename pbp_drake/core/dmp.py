"""Discrete Dynamical Movement Primitives (DMPs) in D dimensions, and a bank of K of them.

Notation (as in Ijspeert et al. 2013): `y` position, `z = tau * dy/dt` scaled velocity,
`x` phase, `g` goal, `y0` start, `tau` duration. Two formulations, chosen by name:

- ``"ijspeert"`` (the paper's form):
  `tau dz = alpha_z (beta_z (g - y) - z) + f(x)`, `f(x) = (psi.w / sum psi) x (g - y0)`;
- ``"pastor"`` (Pastor et al. 2009, Hoffmann et al. 2009; robust to goal changes and to
  `g` close to `y0`): `tau dz = K (g - y) - D z - K (g - y0) x + K (psi.w / sum psi) x`.

With `K = alpha_z beta_z` and `D = alpha_z`, both read `tau dz = K (y_attr - y) - D z`
around a moving attractor

- ijspeert: `y_attr = g + (psi.w / sum psi) x a / K`, `a = g - y0` (or 1 where the
  demonstration's amplitude guard switched the scaling off);
- pastor:   `y_attr = g - (g - y0) x + (psi.w / sum psi) x`,

so a single exact zero-order-hold step (forcing held over the step) serves both, at the
cost of one 2x2 matrix shared by every goal and dimension.

PBP re-integrates the DMP every control step from the robot's measured position. The DMP
keeps its own velocity state: resetting it to the robot's measured velocity each step stalls
the DMP behind a lagging tracker (see DMP_NOTES.md). Only while the phase is locked (the
operator is driving, PBP-Alt) does the DMP's velocity follow the robot's, so that it resumes
from the robot's actual state when the operator lets go.
"""

import dataclasses
import math

import numpy as np

from pbp_drake.core.linear import second_order_transition

FORMULATIONS = ("ijspeert", "pastor")


@dataclasses.dataclass(frozen=True)
class DmpSettings:
    """Gains and basis of a DMP; the defaults are those of DMP_NOTES.md.

    Attributes:
        formulation: "ijspeert" or "pastor".
        basis_count: number of Gaussian basis functions.
        alpha_z: damping gain; `beta_z` defaults to `alpha_z / 4` (critically damped).
        beta_z: stiffness ratio, `None` for `alpha_z / 4`.
        alpha_x: phase decay; `ln 100` makes the phase reach 0.01 at `t = tau`.
    """

    formulation: str = "ijspeert"
    basis_count: int = 50
    alpha_z: float = 25.0
    beta_z: float | None = None
    alpha_x: float = math.log(100.0)

    def __post_init__(self):
        if self.formulation not in FORMULATIONS:
            raise ValueError(
                f"formulation {self.formulation!r} is unknown; choose one of {FORMULATIONS}"
            )
        if self.basis_count < 2:
            raise ValueError(f"basis_count must be at least 2, got {self.basis_count}")
        for name in ("alpha_z", "alpha_x"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name} must be positive, got {getattr(self, name)}")
        if self.beta_z is not None and not self.beta_z > 0:
            raise ValueError(f"beta_z must be positive, got {self.beta_z}")

    @property
    def stiffness(self):
        """`K = alpha_z beta_z`."""
        beta_z = self.alpha_z / 4.0 if self.beta_z is None else self.beta_z
        return self.alpha_z * beta_z

    @property
    def damping(self):
        """`D = alpha_z`."""
        return self.alpha_z

    def basis(self):
        """Centres `c_i = exp(-alpha_x i / (N - 1))` and widths crossing neighbours at 0.7."""
        n = self.basis_count
        centres = np.exp(-self.alpha_x * np.arange(n) / (n - 1))
        widths = np.empty(n)
        widths[:-1] = 4.0 * math.log(1.0 / 0.7) / np.diff(centres) ** 2
        widths[-1] = widths[-2]
        return centres, widths


def normalized_basis(phase, centres, widths):
    """`psi_i(x) / sum_j psi_j(x)` for phases of any shape: returns `(N,) + phase.shape`."""
    phase = np.asarray(phase, dtype=float)
    offsets = phase[np.newaxis, ...] - centres.reshape((-1,) + (1,) * phase.ndim)
    psi = np.exp(-widths.reshape((-1,) + (1,) * phase.ndim) * offsets**2)
    return psi / psi.sum(axis=0)


def minimum_jerk(start, goal, duration, sample_count=200):
    """Times `(T,)` and positions `(T, D)` of a minimum-jerk straight path, rest to rest."""
    start = _as_point(start, "start")
    goal = _as_point(goal, "goal", dimension=start.size)
    times = np.linspace(0.0, duration, sample_count)
    s = times / duration
    progress = 10 * s**3 - 15 * s**4 + 6 * s**5
    return times, start + np.outer(progress, goal - start)


def validate_demonstration(times, positions):
    """Checks a demonstration and returns it as float arrays `(T,)`, `(T, D)`."""
    positions = np.asarray(positions, dtype=float)
    if positions.ndim == 1:
        positions = positions[:, np.newaxis]
    if positions.ndim != 2:
        raise ValueError(f"demonstration positions must be (T, D), got shape {positions.shape}")
    if positions.shape[0] < 3:
        raise ValueError(
            f"demonstration has {positions.shape[0]} samples; at least 3 are needed"
        )
    bad = np.flatnonzero(~np.isfinite(positions).all(axis=1))
    if bad.size:
        raise ValueError(f"demonstration positions are NaN or infinite at sample {bad[0]}")
    times = np.asarray(times, dtype=float)
    if times.shape != (positions.shape[0],):
        raise ValueError(
            f"demonstration times have shape {times.shape}, expected ({positions.shape[0]},)"
        )
    if not np.isfinite(times).all() or not (np.diff(times) > 0).all():
        raise ValueError("demonstration times must be finite and strictly increasing")
    return times, positions


def fit_weights(times, positions, settings=DmpSettings()):
    """Forcing-term weights `(N, D)` from ONE demonstration by locally weighted regression.

    Returns `(weights, amplitude_scaling)`; `amplitude_scaling[d]` is False where the
    Ijspeert `(g - y0)` factor was switched off because the demonstration's amplitude is over
    twice its start-to-goal distance (the reference code's guard, which also covers `g = y0`).
    """
    times, positions = validate_demonstration(times, positions)
    elapsed = times - times[0]
    tau = elapsed[-1]
    start, goal = positions[0], positions[-1]
    velocity = np.gradient(positions, elapsed, axis=0)
    acceleration = np.gradient(velocity, elapsed, axis=0)
    phase = np.exp(-settings.alpha_x * elapsed / tau)
    k, d = settings.stiffness, settings.damping
    # The attractor the demonstration implies: tau dz = K (y_attr - y) - D z, solved for y_attr.
    attractor = positions + (tau**2 * acceleration + d * tau * velocity) / k

    span = goal - start
    amplitude = positions.max(axis=0) - positions.min(axis=0)
    amplitude_scaling = amplitude <= 2.0 * np.abs(span)
    if settings.formulation == "ijspeert":
        scale = np.where(amplitude_scaling, span, 1.0)
        target = attractor - goal
        regressor = np.outer(phase, scale) / k
    else:
        target = attractor - goal + np.outer(phase, span)
        regressor = np.repeat(phase[:, np.newaxis], positions.shape[1], axis=1)
        amplitude_scaling = np.zeros_like(amplitude_scaling)

    centres, widths = settings.basis()
    psi = np.exp(-widths[:, np.newaxis] * (phase[np.newaxis, :] - centres[:, np.newaxis]) ** 2)
    numerator = psi @ (regressor * target)
    denominator = psi @ (regressor**2)
    weights = np.divide(
        numerator, denominator, out=np.zeros_like(numerator), where=denominator > 1e-300
    )
    return weights, amplitude_scaling


class Dmp:
    """One DMP in D dimensions, stepped with a plain per-dimension loop.

    The reference implementation for a single goal: readable, and the oracle the vectorised
    `DmpBank` is tested against.
    """

    def __init__(self, weights, start, goal, duration, settings=DmpSettings(),
                 amplitude_scaling=None):
        self.settings = settings
        self.start = _as_point(start, "start")
        self.goal = _as_point(goal, "goal", dimension=self.start.size)
        self.weights = np.asarray(weights, dtype=float).reshape(settings.basis_count, -1)
        if self.weights.shape[1] != self.start.size:
            raise ValueError(
                f"weights have {self.weights.shape[1]} dimensions, start has {self.start.size}"
            )
        self.duration = _positive(duration, "duration")
        self.amplitude_scaling = (
            np.ones(self.start.size, bool)
            if amplitude_scaling is None
            else np.asarray(amplitude_scaling, bool).reshape(self.start.size)
        )
        self._centres, self._widths = settings.basis()
        self.reset()

    @classmethod
    def from_demonstration(cls, times, positions, settings=DmpSettings()):
        """Learns the DMP of ONE demonstration; start, goal and duration are the demo's."""
        times, positions = validate_demonstration(times, positions)
        weights, scaling = fit_weights(times, positions, settings)
        return cls(weights, positions[0], positions[-1], times[-1] - times[0], settings, scaling)

    @classmethod
    def straight(cls, start, goal, duration, settings=DmpSettings(), profile="minimum_jerk"):
        """A DMP with no demonstration: a straight path from `start` to `goal`.

        `profile="minimum_jerk"` fits a minimum-jerk reach (bell-shaped speed, done at
        `duration`); `profile="zero_forcing"` uses `f = 0` (straight too, from rest, but with
        the abrupt start of a critically damped spring).
        """
        start = _as_point(start, "start")
        goal = _as_point(goal, "goal", dimension=start.size)
        if profile == "zero_forcing":
            weights = np.zeros((settings.basis_count, start.size))
            return cls(weights, start, goal, duration, settings)
        if profile != "minimum_jerk":
            raise ValueError(f"profile {profile!r} is unknown; use 'minimum_jerk' or 'zero_forcing'")
        # Fit in each dimension on a unit reach so that dimensions with g = y0 still get the
        # straight-path shape; the Ijspeert (g - y0) factor then scales it to any goal.
        times, unit = minimum_jerk(np.zeros(1), np.ones(1), duration)
        unit_weights, _ = fit_weights(times, unit, settings)
        span = goal - start if settings.formulation == "pastor" else np.ones(start.size)
        return cls(unit_weights * span, start, goal, duration, settings)

    def reset(self, position=None, scaled_velocity=None):
        """Phase to 1, position to `start` (or `position`), scaled velocity to 0 (or given)."""
        self.phase = 1.0
        self.position = self.start.copy() if position is None else _as_point(position, "position")
        self.scaled_velocity = (
            np.zeros(self.start.size) if scaled_velocity is None else np.array(scaled_velocity, float)
        )

    def attractor(self, phase, goal):
        """The moving attractor `y_attr(x, g)` of the module docstring, per dimension."""
        psi = np.exp(-self._widths * (phase - self._centres) ** 2)
        shape = (psi @ self.weights) / psi.sum() * phase
        result = np.empty(self.start.size)
        for dim in range(self.start.size):
            if self.settings.formulation == "ijspeert":
                amplitude = goal[dim] - self.start[dim] if self.amplitude_scaling[dim] else 1.0
                result[dim] = goal[dim] + shape[dim] * amplitude / self.settings.stiffness
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
        goal = self.goal if goal is None else _as_point(goal, "goal", dimension=self.start.size)
        if robot_position is not None:
            self.position = _as_point(robot_position, "robot_position", dimension=self.start.size)
        tau = self.duration
        if phase_locked:
            if robot_velocity is not None:
                self.scaled_velocity = tau * np.asarray(robot_velocity, float)
            return self.position.copy(), self.scaled_velocity / tau
        transition = second_order_transition(
            self.settings.stiffness, self.settings.damping, tau, dt
        )
        attractor = self.attractor(self.phase, goal)
        for dim in range(self.start.size):
            offset = self.position[dim] - attractor[dim]
            z = self.scaled_velocity[dim]
            self.position[dim] = attractor[dim] + transition[0, 0] * offset + transition[0, 1] * z
            self.scaled_velocity[dim] = transition[1, 0] * offset + transition[1, 1] * z
        self.phase *= math.exp(-self.settings.alpha_x * dt / tau)
        return self.position.copy(), self.scaled_velocity / tau

    def rollout(self, dt, duration=None):
        """Open-loop positions `(steps + 1, D)` from the current state, the state kept."""
        saved = (self.phase, self.position.copy(), self.scaled_velocity.copy())
        steps = int(round((self.duration if duration is None else duration) / dt))
        path = [self.position.copy()]
        for _ in range(steps):
            path.append(self.next_step(dt)[0])
        self.phase, self.position, self.scaled_velocity = saved
        return np.array(path)


class DmpBank:
    """K DMPs, one per goal, stepped together from one shared robot state.

    Vectorised over goals and dimensions; arrays are laid out `(D, K)` internally. All DMPs
    share `duration` and `settings` (so one 2x2 transition serves all of them); each has its
    own weights (or all share one set, e.g. straight paths or one demonstration), its own
    start and its own phase.

    Use it statefully, as NumPy users would (`reset`, then `next_step(goals, y_robot)` each
    control step), or through the pure `advance` that Drake's `DmpBank` system calls with the
    state it keeps in its Context.
    """

    def __init__(self, weights, starts, duration, settings=DmpSettings(),
                 amplitude_scaling=None, goal_count=None):
        self.settings = settings
        self.duration = _positive(duration, "duration")
        weights = np.asarray(weights, dtype=float)
        starts = np.asarray(starts, dtype=float)
        if weights.ndim == 2:
            # One set of weights for every goal: shared work, one (N, D) matrix.
            self.shared_weights = True
            if goal_count is None:
                goal_count = 1 if starts.ndim == 1 else starts.shape[0]
            self._weights = weights
            dimension = weights.shape[1]
        elif weights.ndim == 3:
            self.shared_weights = False
            goal_count = weights.shape[0]
            dimension = weights.shape[2]
            self._weights = np.ascontiguousarray(weights.transpose(1, 2, 0))  # (N, D, K)
        else:
            raise ValueError(f"weights must be (N, D) or (K, N, D), got shape {weights.shape}")
        if weights.shape[-2] != settings.basis_count:
            raise ValueError(
                f"weights have {weights.shape[-2]} basis functions, settings say "
                f"{settings.basis_count}"
            )
        if goal_count < 1:
            raise ValueError("a DMP bank needs at least one goal")
        self.goal_count = goal_count
        self.dimension = dimension
        self.starts = _broadcast_goalwise(starts, goal_count, dimension, "starts")  # (D, K)
        scaling = np.ones((goal_count, dimension), bool) if amplitude_scaling is None else (
            np.broadcast_to(np.asarray(amplitude_scaling, bool), (goal_count, dimension)))
        self.amplitude_scaling = np.ascontiguousarray(scaling.T)
        self._centres, self._widths = settings.basis()
        self._transitions = {}
        self.reset()

    @classmethod
    def from_dmps(cls, dmps):
        """A bank of the given single DMPs (same duration and settings)."""
        if not dmps:
            raise ValueError("a DMP bank needs at least one DMP")
        first = dmps[0]
        for other in dmps[1:]:
            if other.duration != first.duration or other.settings != first.settings:
                raise ValueError("all DMPs of a bank must share duration and settings")
        return cls(
            np.stack([dmp.weights for dmp in dmps]),
            np.stack([dmp.start for dmp in dmps]),
            first.duration,
            first.settings,
            np.stack([dmp.amplitude_scaling for dmp in dmps]),
        )

    @classmethod
    def from_demonstration(cls, times, positions, goal_count=1, settings=DmpSettings(),
                           start=None, duration=None):
        """K DMPs that share ONE demonstration's shape, sent to K goals given at run time.

        The Ijspeert form rescales the shape by each goal's `(g - y0)`; the Pastor form keeps
        it as learned. `duration` (tau) defaults to the demonstration's.
        """
        times, positions = validate_demonstration(times, positions)
        weights, scaling = fit_weights(times, positions, settings)
        start = positions[0] if start is None else start
        duration = times[-1] - times[0] if duration is None else duration
        return cls(weights, start, duration, settings, scaling, goal_count)

    @classmethod
    def straight(cls, start, goal_count, duration, settings=DmpSettings()):
        """K straight-path DMPs from `start` to goals given at run time (no demonstration).

        Ijspeert: the minimum-jerk shape, shared by all goals (it scales with `g - y0`).
        Pastor: `f = 0`, whose attractor already slides from `y0` to `g` along the line.
        """
        dimension = _as_point(start, "start").size
        if settings.formulation == "ijspeert":
            unit = Dmp.straight(np.zeros(1), np.ones(1), duration, settings)
            weights = np.repeat(unit.weights, dimension, axis=1)
        else:
            weights = np.zeros((settings.basis_count, dimension))
        return cls(weights, start, duration, settings, goal_count=goal_count)

    def initial_state(self, position=None):
        """(phase (K,), position (D, K), scaled velocity (D, K)) at the start of a movement."""
        positions = self.starts.copy() if position is None else np.repeat(
            _as_point(position, "position", dimension=self.dimension)[:, None],
            self.goal_count, axis=1)
        return (np.ones(self.goal_count), positions,
                np.zeros((self.dimension, self.goal_count)))

    def reset(self, position=None):
        self.phase, self.position, self.scaled_velocity = self.initial_state(position)

    def goals_matrix(self, goals):
        """Validates goals given as `(K, D)` (or flat `K*D`) and returns them as `(D, K)`."""
        goals = np.asarray(goals, dtype=float)
        if goals.size == 0:
            raise ValueError("goals is empty: give at least one goal")
        if goals.size != self.goal_count * self.dimension:
            raise ValueError(
                f"goals has {goals.size} numbers; the bank expects {self.goal_count} goals of "
                f"dimension {self.dimension}"
            )
        if not np.isfinite(goals).all():
            raise ValueError("goals contains NaN or infinite values")
        return goals.reshape(self.goal_count, self.dimension).T

    def transition(self, dt):
        if dt not in self._transitions:
            self._transitions[dt] = second_order_transition(
                self.settings.stiffness, self.settings.damping, self.duration, dt
            )
        return self._transitions[dt]

    def attractors(self, phase, goals_dk):
        """The moving attractors `(D, K)` for phases `(K,)` and goals `(D, K)`."""
        phi = normalized_basis(phase, self._centres, self._widths)  # (N, K)
        if self.shared_weights:
            shape = self._weights.T @ phi  # (D, K)
        else:
            shape = np.einsum("nk,ndk->dk", phi, self._weights)
        shape *= phase
        if self.settings.formulation == "ijspeert":
            amplitude = np.where(self.amplitude_scaling, goals_dk - self.starts, 1.0)
            return goals_dk + shape * amplitude / self.settings.stiffness
        return goals_dk - (goals_dk - self.starts) * phase + shape

    def advance(self, phase, positions, scaled_velocity, goals_dk, dt, locked=None,
                robot_velocity=None):
        """One exact zero-order-hold step of all K DMPs; pure: returns the new state.

        Args:
            phase: (K,) phases; positions: (D, K) or (D, 1) positions to step from (PBP passes
                the robot's position); scaled_velocity: (D, K) the DMPs' own `z`.
            goals_dk: (D, K) goals.
            locked: None, or a bool (or (K,) bools) freezing those DMPs' phases; their
                velocity then follows `robot_velocity` (D,) and their position stays.
        Returns:
            (phase, positions, scaled_velocity) after the step, new arrays.
        """
        positions = np.broadcast_to(positions, scaled_velocity.shape)
        transition = self.transition(dt)
        attractor = self.attractors(phase, goals_dk)
        offset = positions - attractor
        new_positions = attractor + transition[0, 0] * offset + transition[0, 1] * scaled_velocity
        new_velocity = transition[1, 0] * offset + transition[1, 1] * scaled_velocity
        new_phase = phase * math.exp(-self.settings.alpha_x * dt / self.duration)
        if locked is not None and np.any(locked):
            locked = np.broadcast_to(np.asarray(locked, bool), phase.shape)
            new_phase = np.where(locked, phase, new_phase)
            new_positions = np.where(locked, positions, new_positions)
            held = (scaled_velocity if robot_velocity is None
                    else self.duration * np.asarray(robot_velocity, float)[:, None])
            new_velocity = np.where(locked, held, new_velocity)
        return new_phase, new_positions, new_velocity

    def next_step(self, goals, y_robot, dt, yd_robot=None, phase_locked=False):
        """Stateful step from the robot's position: returns positions and velocities `(K, D)`.

        `yd_robot` is used only while `phase_locked` (see the module docstring).
        """
        robot = _as_point(y_robot, "y_robot", dimension=self.dimension)[:, None]
        self.phase, self.position, self.scaled_velocity = self.advance(
            self.phase, robot, self.scaled_velocity, self.goals_matrix(goals), dt,
            locked=phase_locked if phase_locked else None, robot_velocity=yd_robot)
        return self.position.T.copy(), (self.scaled_velocity / self.duration).T.copy()

    def predict(self, phase, position, scaled_velocity, goals_dk, dt, steps):
        """Open-loop paths `(K, steps + 1, D)` from one state, for drawing predictions."""
        path = np.empty((steps + 1, self.dimension, self.goal_count))
        positions = np.broadcast_to(position, scaled_velocity.shape).copy()
        path[0] = positions
        for step in range(steps):
            phase, positions, scaled_velocity = self.advance(
                phase, positions, scaled_velocity, goals_dk, dt)
            path[step + 1] = positions
        return path.transpose(2, 0, 1)


def _as_point(value, name, dimension=None):
    point = np.array(value, dtype=float).reshape(-1)
    if point.size == 0:
        raise ValueError(f"{name} is empty")
    if dimension is not None and point.size != dimension:
        raise ValueError(f"{name} has {point.size} numbers, expected {dimension}")
    if not np.isfinite(point).all():
        raise ValueError(f"{name} contains NaN or infinite values: {point}")
    return point


def _positive(value, name):
    if not (np.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be positive and finite, got {value}")
    return float(value)


def _broadcast_goalwise(values, goal_count, dimension, name):
    values = np.asarray(values, dtype=float)
    if values.ndim == 1:
        values = np.broadcast_to(values, (goal_count, values.size))
    if values.shape != (goal_count, dimension):
        raise ValueError(f"{name} must be ({goal_count}, {dimension}) or ({dimension},)")
    if not np.isfinite(values).all():
        raise ValueError(f"{name} contains NaN or infinite values")
    return np.ascontiguousarray(values.T)
