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


@dataclasses.dataclass
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
        self.validate()

    def validate(self):
        """Raises ValueError naming the first field that cannot be used (a YAML loader sets
        the fields after construction, so `resolve` calls this again)."""
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
    control step), or through the pure `advance`; `advance_into` is the same step written
    into arrays the caller owns, with no allocation, and `offsets_into`,
    `stepped_positions_into` and `stepped_velocity_into` are its parts (Drake's `DmpBank`
    system keeps the offsets in its Context and reads the stepped state out on demand).

    Speed. When all phases are equal (DMPs started together and locked together: the normal
    case), the basis is evaluated once, `(N,)`, and contracted with the weights: shared
    weights give a `(D,)` shape broadcast to all goals (O(N D + D K)); distinct weights are
    one `(N,) x (N, D*K)` matrix-vector product over contiguous memory (memory bound). The
    per-goal-phase path (phases made unequal by per-goal locks) evaluates `(N, K)` bases.
    With shared weights, equal phases and one start, the attractor is affine in the goal
    with per-dimension coefficients, so no per-goal shape is ever formed. The step then
    makes a fixed number of passes over `(D, K)` work arrays kept in the bank, using the
    one cached 2x2 transition. `amplitude_scaling` and `starts` are read at construction.
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
        self._decays = {}
        self._allocate_work()
        self.reset()

    def _allocate_work(self):
        """Work arrays reused by every step (so that a step allocates nothing)."""
        d, k, n = self.dimension, self.goal_count, self.settings.basis_count
        self._negative_widths = -self._widths
        self._ijspeert = self.settings.formulation == "ijspeert"
        self._unscaled = ~self.amplitude_scaling
        self._all_scaled = not self._unscaled.any()
        self._psi = np.empty(n)
        self._coefficients = np.empty(d)
        self._coefficient_column = self._coefficients[:, np.newaxis]
        self._shape = np.empty((d, k))
        self._shape_flat = self._shape.reshape(-1)
        self._attractor = np.empty((d, k))
        self._offset = np.empty((d, k))
        self._work = np.empty((d, k))
        # Shared weights, a per-dimension amplitude scaling and one start: with equal phases
        # the attractor is `alpha_g g + alpha_c` per dimension (see `offsets_into`).
        scaling = self.amplitude_scaling
        starts = self.starts
        self._affine_attractor = (
            self.shared_weights and bool((scaling.all(axis=1) | ~scaling.any(axis=1)).all())
            and bool((starts == starts[:, :1]).all()))
        self._uniform_start = starts[:, :1].copy()
        self._scaled_dimensions = scaling[:, :1].astype(float)
        self._alpha_goal = np.empty((d, 1))
        self._alpha_constant = np.empty((d, 1))
        self._column = np.empty((d, 1))

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
        # One reduction without a temporary: a finite sum proves every entry finite; only
        # when it is not (NaN, infinity, or an overflow of huge finite goals) look closer.
        if not math.isfinite(goals.sum()) and not np.isfinite(goals).all():
            raise ValueError("goals contains NaN or infinite values")
        return goals.reshape(self.goal_count, self.dimension).T

    def transition(self, dt):
        if dt not in self._transitions:
            self._transitions[dt] = second_order_transition(
                self.settings.stiffness, self.settings.damping, self.duration, dt
            )
        return self._transitions[dt]

    def decay(self, dt):
        """The phase factor `exp(-alpha_x dt / tau)` of one step (cached per `dt`)."""
        factor = self._decays.get(dt)
        if factor is None:
            factor = self._decays[dt] = math.exp(-self.settings.alpha_x * dt / self.duration)
        return factor

    def attractors(self, phase, goals_dk):
        """The moving attractors `(D, K)` for phases `(K,)` and goals `(D, K)`."""
        return self._attractors_into(np.asarray(phase, dtype=float), goals_dk).copy()

    def _attractors_into(self, phase, goals_dk):
        """The attractors written into the bank's work array (returned; valid until the next
        call)."""
        shape, x = self._shaped_forcing(phase)  # shape already times x (and / K)
        attractor = self._attractor
        np.subtract(goals_dk, self.starts, out=attractor)
        if self._ijspeert:
            # g + shape x (g - y0) / K, with 1 for (g - y0) where the scaling is off.
            if not self._all_scaled:
                np.copyto(attractor, 1.0, where=self._unscaled)
            attractor *= shape
            attractor += goals_dk
        else:
            # g - (g - y0) x + shape x
            attractor *= x
            np.subtract(goals_dk, attractor, out=attractor)
            attractor += shape
        return attractor

    def _shaped_forcing(self, phase):
        """`(psi.w / sum psi) x`, divided by K in the Ijspeert form, and the phase.

        Equal phases: the shape is `(D, 1)` (shared weights) or `(D, K)`, the phase a float;
        a phase per goal: the shape is `(D, K)`, the phase `(K,)`. The shape is a work array.
        """
        if phase.size == 1 or phase.min() == phase.max():
            x = float(phase.flat[0])
            psi = self._psi
            np.subtract(x, self._centres, out=psi)
            np.square(psi, out=psi)
            psi *= self._negative_widths
            np.exp(psi, out=psi)
            scale = x / psi.sum()
            if self._ijspeert:
                scale /= self.settings.stiffness
            psi *= scale
            if self.shared_weights:
                np.dot(psi, self._weights, out=self._coefficients)
                return self._coefficient_column, x
            n = self.settings.basis_count
            np.dot(psi, self._weights.reshape(n, -1), out=self._shape_flat)
            return self._shape, x
        # A phase per goal: K bases.
        phi = normalized_basis(phase, self._centres, self._widths)  # (N, K)
        shape = self._shape
        if self.shared_weights:
            np.matmul(self._weights.T, phi, out=shape)
        else:
            np.einsum("nk,ndk->dk", phi, self._weights, out=shape)
        shape *= phase
        if self._ijspeert:
            shape /= self.settings.stiffness
        return shape, phase

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
        phase = np.asarray(phase, dtype=float)
        scaled_velocity = np.asarray(scaled_velocity, dtype=float)
        new_phase = np.empty(phase.shape)
        new_positions = np.empty(scaled_velocity.shape)
        new_velocity = np.empty(scaled_velocity.shape)
        self.advance_into(phase, positions, scaled_velocity, goals_dk, dt,
                          new_phase, new_positions, new_velocity, locked, robot_velocity)
        return new_phase, new_positions, new_velocity

    def advance_into(self, phase, positions, scaled_velocity, goals_dk, dt,
                     out_phase, out_positions, out_velocity, locked=None, robot_velocity=None):
        """`advance` written into `out_phase` (K,), `out_positions` and `out_velocity` (D, K).

        The outputs may be the inputs themselves (`out_phase is phase`,
        `out_velocity is scaled_velocity`, `out_positions is positions`): the step then
        updates the state in place. Allocates nothing unless some (not all) DMPs are locked.
        """
        if locked is not None and not isinstance(locked, (bool, np.bool_)):
            locked = np.asarray(locked, bool)
            if locked.ndim == 0 or locked.all():
                locked = bool(locked.all())
            elif not locked.any():
                locked = False
            else:
                return self._advance_partly_locked(
                    phase, positions, scaled_velocity, goals_dk, dt, out_phase, out_positions,
                    out_velocity, np.broadcast_to(locked, np.shape(phase)), robot_velocity)
        if locked:
            # Every phase frozen: the DMPs stay at the given positions and follow the robot.
            if out_phase is not phase:
                out_phase[...] = phase
            if out_positions is not positions:
                out_positions[...] = positions
            if robot_velocity is not None:
                np.multiply(np.asarray(robot_velocity, float)[:, np.newaxis], self.duration,
                            out=out_velocity)
            elif out_velocity is not scaled_velocity:
                out_velocity[...] = scaled_velocity
            return
        offset = self.offsets_into(phase, positions, goals_dk, self._offset)
        # Positions first: `out_velocity` may alias `scaled_velocity`, which they read.
        self.stepped_positions_into(positions, offset, scaled_velocity, dt, out_positions)
        self.stepped_velocity_into(offset, scaled_velocity, dt, out_velocity)
        np.multiply(phase, self.decay(dt), out=out_phase)

    # The step, in parts. With `offset = y - a` (the position stepped from minus the
    # attractor), the exact zero-order-hold step is
    #     y' = y + (Phi00 - 1) offset + Phi01 z,    z' = Phi10 offset + Phi11 z,
    # so a caller may keep `(offset, z)` and read `(y', z')` out later (Drake's DmpBank does:
    # PBP never feeds the DMPs' own positions back, only the robot's).

    def offsets_into(self, phase, positions, goals_dk, out):
        """`out = positions - attractor(phase, goals)`, `(D, K)`; `positions` (D, K) or
        (D, 1). Two passes over `(D, K)` when the DMPs share weights, phase and start."""
        if self._affine_attractor and (phase.size == 1 or phase.min() == phase.max()):
            negative_alpha_goal, alpha_constant = self._affine_attractor_coefficients(phase)
            # positions - (alpha_g g + alpha_c) = -alpha_g g + (positions - alpha_c)
            np.multiply(goals_dk, negative_alpha_goal, out=out)
            if positions.shape[1] == 1:
                np.subtract(positions, alpha_constant, out=self._column)
                out += self._column
            else:
                out += positions
                out -= alpha_constant
            return out
        np.subtract(positions, self._attractors_into(phase, goals_dk), out=out)
        return out

    def stepped_positions_into(self, positions, offset, scaled_velocity, dt, out):
        """`out = positions + (Phi00 - 1) offset + Phi01 z`: the positions after the step."""
        (t00, t01), _ = self.transition(dt)
        work = self._work
        np.multiply(offset, t00 - 1.0, out=work)
        np.add(positions, work, out=out)  # `out` may be `positions`
        np.multiply(scaled_velocity, t01, out=work)
        out += work
        return out

    def stepped_velocity_into(self, offset, scaled_velocity, dt, out, scratch=None):
        """`out = Phi10 offset + Phi11 z`: the scaled velocities after the step (`out` may be
        `scaled_velocity`). `scratch` (D, K) holds `Phi10 offset` (default: the bank's work
        array); a caller done with `offset` may pass `offset` itself, all passes in place."""
        _, (t10, t11) = self.transition(dt)
        scratch = self._work if scratch is None else scratch
        np.multiply(offset, t10, out=scratch)
        np.multiply(scaled_velocity, t11, out=out)
        out += scratch
        return out

    def _affine_attractor_coefficients(self, phase):
        """Per dimension `(-alpha_g, alpha_c)` `(D, 1)` with `attractor = alpha_g g + alpha_c`
        for every goal: shared weights, one phase and one start make it affine in g."""
        shape, x = self._shaped_forcing(phase)  # (D, 1): the forcing (times x, / K)
        alpha_goal, alpha_constant = self._alpha_goal, self._alpha_constant
        start = self._uniform_start
        if self._ijspeert:
            # a = g + c (g - y0) where scaled, g + c where not.
            scaled = self._scaled_dimensions
            np.multiply(shape, scaled, out=alpha_goal)
            np.multiply(alpha_goal, -start, out=alpha_constant)
            alpha_constant += shape
            alpha_constant -= alpha_goal
            alpha_goal += 1.0
        else:
            # a = g - (g - y0) x + c.
            alpha_goal.fill(1.0 - x)
            np.multiply(start, x, out=alpha_constant)
            alpha_constant += shape
        np.negative(alpha_goal, out=alpha_goal)
        return alpha_goal, alpha_constant

    def _advance_partly_locked(self, phase, positions, scaled_velocity, goals_dk, dt,
                               out_phase, out_positions, out_velocity, locked,
                               robot_velocity):
        """Some DMPs locked, some not: the plain path with temporaries (rare)."""
        phase = np.array(phase, dtype=float)
        positions = np.array(np.broadcast_to(positions, np.shape(scaled_velocity)), float)
        scaled_velocity = np.array(scaled_velocity, dtype=float)
        new_phase = np.empty_like(phase)
        new_positions = np.empty_like(scaled_velocity)
        new_velocity = np.empty_like(scaled_velocity)
        self.advance_into(phase, positions, scaled_velocity, goals_dk, dt,
                          new_phase, new_positions, new_velocity)
        held = (scaled_velocity if robot_velocity is None
                else self.duration * np.asarray(robot_velocity, float)[:, None])
        out_phase[...] = np.where(locked, phase, new_phase)
        out_positions[...] = np.where(locked, positions, new_positions)
        out_velocity[...] = np.where(locked, held, new_velocity)

    def next_step(self, goals, y_robot, dt, yd_robot=None, phase_locked=False):
        """Stateful step from the robot's position: returns positions and velocities `(K, D)`.

        `yd_robot` is used only while `phase_locked` (see the module docstring). The bank's
        `phase`, `position` and `scaled_velocity` arrays are updated in place.
        """
        robot = _as_point(y_robot, "y_robot", dimension=self.dimension)[:, None]
        self.advance_into(
            self.phase, robot, self.scaled_velocity, self.goals_matrix(goals), dt,
            self.phase, self.position, self.scaled_velocity,
            locked=phase_locked if phase_locked is not False else None,
            robot_velocity=yd_robot)
        return self.position.T.copy(), (self.scaled_velocity / self.duration).T.copy()

    def predict(self, phase, position, scaled_velocity, goals_dk, dt, steps):
        """Open-loop paths `(K, steps + 1, D)` from one state, for drawing predictions."""
        path = np.empty((steps + 1, self.dimension, self.goal_count))
        path[0] = np.broadcast_to(position, np.shape(scaled_velocity))
        phase = np.array(phase, dtype=float)
        scaled_velocity = np.array(scaled_velocity, dtype=float)
        for step in range(steps):
            self.advance_into(phase, path[step], scaled_velocity, goals_dk, dt,
                              phase, path[step + 1], scaled_velocity)
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
