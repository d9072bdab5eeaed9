"""K orientation DMPs, one per goal orientation, as one immutable model stepped by a pure
function vectorised over goals (the formulation: `pbp_drake.core.dmp.orientation`).

The API is the position `DmpBank`'s, with orientations for positions, so that a 6-DoF bank
can step both halves side by side: the state is `(phase (K,), orientations (4, K),
scaled angular velocities (3, K))`, `eta = tau omega` in the world frame; goals are `(4, K)`
(`goals_matrix` checks `(K, 4)` rows); `advance` steps from the robot's measured orientation
`(4, 1)` (or one per DMP, `(4, K)`) and the DMPs' own `eta`. The two banks share the phase
variable: given the same settings, `tau` and `locked`, their phases stay equal, and
PBP-Alt's lock is the same `locked` flag passed to both.

The step is the position bank's first-order-hold step on `e = Log(q g*)` (3, K), with the
memoised `stepping.step_constants`: the basis is evaluated at the step's two phases only
when the phases are equal (the normal case), and contracted with the weights once.
"""

import dataclasses

import numpy as np

from pbp_drake.core import quaternion
from pbp_drake.core.dmp._checks import positive
from pbp_drake.core.dmp.orientation import (
    AXES, OrientationDmp, fit_orientation_weights, orientation_errors, straight_weights,
    validate_orientation_demonstration)
from pbp_drake.core.dmp.settings import DmpSettings, normalized_basis, phase_decay
from pbp_drake.core.dmp.stepping import step_constants


def _read_only(array):
    """A private read-only copy: the model must not change under its users."""
    array = np.array(array, dtype=float, order="C")
    array.setflags(write=False)
    return array


class OrientationDmpBank:
    """K orientation DMPs, stepped together from one measured orientation.

    All share `duration` and `settings`; each has its own start orientation and phase, and
    its own weights `(K, N, 3)` or one set `(N, 3)` shared by all (straight paths, or one
    demonstration sent to K goals). Immutable: the state is passed in and out of `advance`.
    """

    def __init__(self, weights, starts, duration, settings=DmpSettings(),
                 amplitude_scaling=None, goal_count=None):
        settings.validate()
        self._settings = dataclasses.replace(settings)
        self.duration = positive(duration, "duration")
        weights = np.asarray(weights, dtype=float)
        starts = quaternion.unit_quaternions(starts, "starts")
        if weights.ndim == 2:
            self.shared_weights = True
            if goal_count is None:
                goal_count = 1 if starts.ndim == 1 else starts.shape[0]
            self._weights = _read_only(weights)  # (N, 3)
        elif weights.ndim == 3:
            self.shared_weights = False
            goal_count = weights.shape[0]
            # (N, 3 K): the step contracts it with the basis in one product.
            self._weights = _read_only(weights.transpose(1, 2, 0).reshape(weights.shape[1], -1))
        else:
            raise ValueError(f"weights must be (N, 3) or (K, N, 3), got shape {weights.shape}")
        if weights.shape[-2:] != (settings.basis_count, AXES):
            raise ValueError(f"weights must have {settings.basis_count} basis functions "
                             f"(the settings') and 3 axes, got shape {weights.shape}")
        if goal_count < 1:
            raise ValueError("an orientation DMP bank needs at least one goal")
        self.goal_count = goal_count
        self.dimension = AXES
        if starts.ndim == 1:
            starts = np.broadcast_to(starts, (goal_count, 4))
        if starts.shape != (goal_count, 4):
            raise ValueError(f"starts must be ({goal_count}, 4) or (4,), got {starts.shape}")
        self.starts = _read_only(starts.T)  # (4, K)
        scaling = (np.ones((goal_count, AXES), bool) if amplitude_scaling is None else
                   np.broadcast_to(np.asarray(amplitude_scaling, bool), (goal_count, AXES)))
        self.amplitude_scaling = np.array(scaling.T)  # (3, K)
        self.amplitude_scaling.setflags(write=False)
        self._all_scaled = bool(scaling.all())
        centres, widths = settings.basis()
        self._centres, self._widths = _read_only(centres), _read_only(widths)
        self._frozen = True

    def __setattr__(self, name, value):
        # Immutable after construction, as the position bank: shared by threads or Contexts.
        if getattr(self, "_frozen", False):
            raise AttributeError(f"OrientationDmpBank is immutable: cannot set {name!r}")
        object.__setattr__(self, name, value)

    @classmethod
    def from_dmps(cls, dmps):
        """A bank of the given single `OrientationDmp`s (same duration and settings)."""
        if not dmps:
            raise ValueError("an orientation DMP bank needs at least one DMP")
        first = dmps[0]
        if any(d.duration != first.duration or d.settings != first.settings for d in dmps):
            raise ValueError("all DMPs of a bank must share duration and settings")
        return cls(np.stack([d.weights for d in dmps]), np.stack([d.start for d in dmps]),
                   first.duration, first.settings,
                   np.stack([d.amplitude_scaling for d in dmps]))

    @classmethod
    def from_demonstration(cls, times, orientations, goal_count=1, settings=DmpSettings(),
                           start=None, duration=None):
        """K DMPs sharing ONE demonstration's shape `(T, 4)`, sent to goals given at run
        time; start and `tau` default to the demonstration's."""
        times, orientations = validate_orientation_demonstration(times, orientations)
        weights, scaling = fit_orientation_weights(times, orientations, settings)
        start = orientations[0] if start is None else start
        duration = times[-1] - times[0] if duration is None else duration
        return cls(weights, start, duration, settings, scaling, goal_count)

    @classmethod
    def straight(cls, start, goal_count, duration, settings=DmpSettings()):
        """K DMPs along the shorter arc (slerp) from `start` to goals given at run time.

        Ijspeert: the minimum-jerk shape, shared, scaled per goal by `-e0`; Pastor: `f = 0`,
        whose attractor `e0 x` already slides along the arc."""
        if settings.formulation == "ijspeert":
            weights = straight_weights(settings, duration, np.ones(AXES))
        else:
            weights = np.zeros((settings.basis_count, AXES))
        return cls(weights, start, duration, settings, goal_count=goal_count)

    @property
    def settings(self):
        """The bank's gains and basis (a copy)."""
        return dataclasses.replace(self._settings)

    def decay(self, dt):
        """The phase factor `exp(-alpha_x dt / tau)` of one step (the position bank's)."""
        return phase_decay(self._settings, self.duration, dt)

    def initial_state(self, orientation=None):
        """(phase (K,), orientations (4, K), scaled angular velocity (3, K)) at the start."""
        orientations = (np.array(self.starts) if orientation is None else np.repeat(
            quaternion.unit_quaternions(orientation, "orientation").reshape(4, 1),
            self.goal_count, axis=1))
        return np.ones(self.goal_count), orientations, np.zeros((AXES, self.goal_count))

    def goals_matrix(self, goals):
        """Checks goal orientations given as `(K, 4)` rows (w, x, y, z) and returns `(4, K)`."""
        goals = quaternion.unit_quaternions(np.reshape(goals, (-1, 4)) if np.size(goals)
                                            else goals, "goals")
        if goals.shape != (self.goal_count, 4):
            raise ValueError(f"goals has {goals.shape[0]} quaternions; the bank expects "
                             f"{self.goal_count}")
        return np.array(goals.T, order="C")

    def attractors(self, phase, goals_4k):
        """The moving attractors `a(x)` `(3, K)` in `e = Log(q g*)` coordinates."""
        phase = np.broadcast_to(np.asarray(phase, dtype=float), (self.goal_count,))
        identity = np.eye(2)
        shapes, lam = self._combined_shapes(phase, 1.0, identity)
        return self._relative_attractor(shapes[0], lam[0], orientation_errors(
            self.starts, goals_4k))

    def advance(self, phase, orientations, scaled_angular_velocity, goals_4k, dt,
                locked=None, robot_angular_velocity=None, followed=None):
        """One step of all K DMPs from the measured orientation; pure, new arrays.

        Args:
            phase: (K,). orientations: (4, 1) the robot's measured orientation (PBP), or
                (4, K) one per DMP; unit within `quaternion.UNIT_TOLERANCE`.
            scaled_angular_velocity: (3, K) the DMPs' own `eta = tau omega`.
            goals_4k: (4, K) goal orientations (`goals_matrix`).
            locked: None, a bool or (K,) bools freezing those phases (PBP-Alt): those DMPs
                stay at the given orientation and `eta` follows `robot_angular_velocity` (3,).
            followed: None, or the index of the DMP the robot followed: every DMP then steps
                from its `eta` (PBP's goal switch, as in the position bank).
        Returns:
            (phase (K,), orientations (4, K), scaled angular velocity (3, K)).
        """
        phase = np.asarray(phase, dtype=float)
        velocity = np.asarray(scaled_angular_velocity, dtype=float)
        orientations = quaternion.unit_quaternions(
            np.asarray(orientations, dtype=float).reshape(4, -1).T, "orientations").T
        if followed is not None:
            if not 0 <= int(followed) < self.goal_count:
                raise ValueError(f"followed {followed} is not one of the {self.goal_count} "
                                 "goals")
            velocity = np.repeat(velocity[:, [int(followed)]], self.goal_count, axis=1)
        if locked is not None:
            locked = np.broadcast_to(np.asarray(locked, bool), phase.shape)
            if not locked.any():
                locked = None
        held_velocity = velocity if robot_angular_velocity is None else np.broadcast_to(
            self.duration * np.asarray(robot_angular_velocity, float).reshape(AXES, 1),
            velocity.shape)
        if locked is not None and locked.all():
            return (phase.copy(), np.array(np.broadcast_to(orientations, (4, phase.size))),
                    np.array(held_velocity))
        new_state = self._step(phase, orientations, velocity, goals_4k, dt)
        if locked is None:
            return new_state
        new_phase, new_orientations, new_velocity = new_state
        return (np.where(locked, phase, new_phase),
                np.where(locked, orientations, new_orientations),
                np.where(locked, held_velocity, new_velocity))

    def predict(self, phase, orientation, scaled_angular_velocity, goals_4k, dt, steps):
        """Open-loop orientations `(K, steps + 1, 4)` from one state (inputs left alone)."""
        path = np.empty((steps + 1, 4, self.goal_count))
        path[0] = np.broadcast_to(orientation, (4, self.goal_count))
        for step in range(steps):
            phase, path[step + 1], scaled_angular_velocity = self.advance(
                phase, path[step], scaled_angular_velocity, goals_4k, dt)
        return path.transpose(2, 0, 1)

    def _step(self, phase, orientations, velocity, goals_4k, dt):
        """The free step (see `pbp_drake.core.dmp.orientation`), vectorised over K."""
        constants = step_constants(self._settings.stiffness, self._settings.damping,
                                   self.duration, dt)
        decay = self.decay(dt)
        errors = orientation_errors(orientations, goals_4k)  # (3, K)
        z = quaternion.left_jacobian_inverse_times(errors, velocity)
        start_errors = orientation_errors(self.starts, goals_4k)
        shapes, lam = self._combined_shapes(phase, decay, constants.combination)
        # dp = (Phi00 - 1) e + (C00 b0 + C01 b1), dz = Phi10 e + (C10 b0 + C11 b1), and
        # e' = e + dp + Phi01 z, z' = dz + Phi11 z (the position bank's step, goal 0).
        new_errors = (errors * (1.0 + constants.position_offset)
                      + self._relative_attractor(shapes[0], lam[0], start_errors)
                      + constants.position_velocity * z)
        new_z = (errors * constants.velocity_offset
                 + self._relative_attractor(shapes[1], lam[1], start_errors)
                 + constants.velocity_velocity * z)
        new_orientations = quaternion.aligned(
            quaternion.multiply(quaternion.exp_map(new_errors), goals_4k), orientations)
        new_velocity = quaternion.left_jacobian_times(new_errors, new_z)
        return phase * decay, new_orientations, new_velocity

    def _relative_attractor(self, shape, lam, start_errors):
        """A combination of attractors, `(3, K)`: Ijspeert `S (-e0)` (S alone where the
        scaling is off), Pastor `S + lambda e0`."""
        if self._settings.formulation == "ijspeert":
            amplitude = -start_errors
            if not self._all_scaled:
                amplitude = np.where(self.amplitude_scaling, amplitude, 1.0)
            return shape * amplitude
        return shape + lam * start_errors

    def _combined_shapes(self, phase, decay, combination):
        """Rows r of `combination` (2x2): `S_r = C_r0 s(x0) + C_r1 s(x1)` with
        `s(x) = (psi.w / sum psi) x` (over K in the Ijspeert form), `(2, 3, 1)` or
        `(2, 3, K)`, and `lambda_r = C_r0 x0 + C_r1 x1`, `(2, 1)` or `(2, K)`."""
        n = self._settings.basis_count
        scale = 1.0 / self._settings.stiffness if self._settings.formulation == "ijspeert" else 1.0
        if phase.size == 1 or phase.min() == phase.max():
            # Equal phases: the basis at the step's two phases only, (N, 2).
            phases = np.array([phase.flat[0], phase.flat[0] * decay])
            scaled = normalized_basis(phases, self._centres, self._widths) * (phases * scale)
            basis = combination @ scaled.T  # (2, N)
            if self.shared_weights:
                return (basis @ self._weights)[:, :, np.newaxis], (combination @ phases)[:, None]
            shapes = (basis @ self._weights).reshape(2, AXES, self.goal_count)
            return shapes, (combination @ phases)[:, None]
        # A phase per goal: (N, 2, K) bases.
        phases = np.stack([phase, phase * decay])
        scaled = normalized_basis(phases, self._centres, self._widths) * (phases * scale)
        combined = np.einsum("rs,nsk->rnk", combination, scaled)  # (2, N, K)
        if self.shared_weights:
            shapes = np.einsum("nd,rnk->rdk", self._weights, combined)
        else:
            weights = self._weights.reshape(n, AXES, self.goal_count)
            shapes = np.einsum("ndk,rnk->rdk", weights, combined)
        return shapes, combination @ phases
