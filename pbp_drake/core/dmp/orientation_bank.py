"""K orientation DMPs, one per goal orientation, as one immutable model: the position
`DmpBankModel`'s API with orientations for positions, so that a six-DoF bank steps both
halves side by side at one phase. The step is the position bank's on `e = Log(q g*)`
(`pbp_drake.core.dmp.orientation`), the quaternion math around it in `orientation_kernels`
and `orientation_log_step`."""

import functools

import numpy as np

from pbp_drake.core import quaternion
from pbp_drake.core.dmp._checks import followed_velocity, read_only
from pbp_drake.core.dmp.bank import BankModel
from pbp_drake.core.dmp.contraction import WeightRows, scaled_weights
from pbp_drake.core.dmp.orientation import (
    AXES, fit_orientation_weights, validate_orientation_demonstration)
from pbp_drake.core.dmp.orientation_kernels import (
    OrientationWorkspace, error_quaternions_into, exp_into, inverse_jacobian_into,
    jacobian_into, log_into, product_into)
from pbp_drake.core.dmp.orientation_log_step import (
    IDENTITY6, forcing_rows, log_step_from_one_into)
from pbp_drake.core.dmp.settings import DmpSettings, normalized_basis
from pbp_drake.core.dmp.stepping import step_constants


@functools.lru_cache(maxsize=64)
def _log_transition(position_offset, position_velocity, velocity_offset, velocity_velocity):
    """`Phi (x) I3` (6, 6), read-only, for `[e'; z'] = (Phi (x) I3) [e; z] + ...`, from
    `StepConstants`' numbers (memoised on plain floats, as `step_constants`)."""
    transition = np.array([[1.0 + position_offset, position_velocity],
                           [velocity_offset, velocity_velocity]])
    matrix = np.kron(transition, np.eye(AXES))
    matrix.setflags(write=False)
    return matrix


class OrientationDmpBank(BankModel):
    """K orientation DMPs, stepped together from one measured orientation.

    All share `duration` and `settings`; each has its own start orientation and phase, and
    its own weights `(K, N, 3)` or one set `(N, 3)` shared by all (straight paths, or one
    demonstration sent to K goals). Immutable: the state is passed in and out of `advance`
    (pure) and `advance_into` (into the caller's arrays, with a workspace). `subset`,
    `predict` and `from_dmps` are `BankModel`'s.
    """

    def __init__(self, weights, starts, duration, settings=DmpSettings(),
                 amplitude_scaling=None, goal_count=None):
        starts = quaternion.unit_quaternions(starts, "starts")
        self._keep_model(weights, starts, duration, settings, amplitude_scaling, goal_count,
                         AXES)
        goal_count = self.goal_count
        if starts.ndim == 1:
            starts = np.broadcast_to(starts, (goal_count, 4))
        if starts.shape != (goal_count, 4):
            raise ValueError(f"starts must be ({goal_count}, 4) or (4,), got {starts.shape}")
        self.starts = read_only(starts.T)  # (4, K)
        self._all_scaled = bool(self.amplitude_scaling.all())
        self._weight_rows = (None if self.shared_weights else WeightRows(
            self._weights.reshape(settings.basis_count, -1)))  # (N, 3 K)
        self._ijspeert = settings.formulation == "ijspeert"
        # One start for all: `q0 g*` is then one 4x4 product (`error_quaternions_into`).
        self._uniform_start = (read_only(self.starts[:, :1])
                               if (self.starts == self.starts[:, :1]).all() else None)
        self._frozen = True

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

    @staticmethod
    def _straight_dimension(start):
        return AXES

    def initial_state(self, orientation=None):
        """(phase (K,), orientations (4, K), scaled angular velocity (3, K)) at the start."""
        orientations = (np.array(self.starts) if orientation is None else np.repeat(
            quaternion.unit_quaternions(orientation, "orientation").reshape(4, 1),
            self.goal_count, axis=1))
        return np.ones(self.goal_count), orientations, np.zeros((AXES, self.goal_count))

    def goals_matrix(self, goals):
        """Checks goal orientations given as `(K, 4)` rows (w, x, y, z) and returns `(4, K)`."""
        size = np.size(goals)
        if size != 4 * self.goal_count:
            raise ValueError(f"goals has {size} numbers; the bank expects {self.goal_count} "
                             "quaternions (w, x, y, z)")
        goals = quaternion.unit_quaternions(np.reshape(goals, (self.goal_count, 4)), "goals")
        return np.array(goals.T, order="C")

    def make_workspace(self):
        """New scratch arrays for `advance_into`; one per thread or Drake Context."""
        return OrientationWorkspace(self.goal_count, self._settings.basis_count)

    def attractors(self, phase, goals_4k):
        """The moving attractors `a(x)` `(3, K)` in `e = Log(q g*)` coordinates, a new array."""
        workspace = self.make_workspace()
        phase = np.broadcast_to(np.asarray(phase, dtype=float), (self.goal_count,))
        shapes, lam = self._combined_shapes(phase, 1.0, np.eye(2), workspace)
        self._start_errors_into(goals_4k, workspace)
        attractor = np.zeros((AXES, self.goal_count))
        self._add_relative_attractor(attractor, shapes[0], lam[0], workspace)
        return attractor

    def advance(self, phase, orientations, scaled_angular_velocity, goals_4k, dt,
                locked=None, robot_angular_velocity=None, followed=None):
        """`DmpBankModel.advance` for orientations: one step of all K DMPs; pure, new arrays
        `(phase (K,), orientations (4, K), scaled angular velocity (3, K))`. `orientations`
        (4, 1) the robot's measured one (PBP) or (4, K) one per DMP, unit within
        `quaternion.UNIT_TOLERANCE`; `scaled_angular_velocity` (3, K) the DMPs' own
        `eta = tau omega`; `goals_4k` (4, K) (`goals_matrix`); `locked` freezes phases (those
        DMPs stay and `eta` follows `robot_angular_velocity` (3,)); `followed` as the
        position bank's."""
        phase = np.asarray(phase, dtype=float)
        velocity = followed_velocity(np.asarray(scaled_angular_velocity, dtype=float),
                                     followed, self.goal_count)
        new_state = (np.empty(phase.shape), np.empty((4, self.goal_count)),
                     np.empty((AXES, self.goal_count)))
        self.advance_into(phase, orientations, velocity, goals_4k, dt, *new_state,
                          self.make_workspace(), locked, robot_angular_velocity)
        return new_state

    def advance_into(self, phase, orientations, scaled_angular_velocity, goals_4k, dt,
                     out_phase, out_orientations, out_velocity, workspace, locked=None,
                     robot_angular_velocity=None):
        """`advance` written into `out_phase` (K,), `out_orientations` (4, K) and
        `out_velocity` (3, K), with `workspace` (`make_workspace`) as scratch.

        The outputs may be the inputs (`out_velocity is scaled_angular_velocity`, ...): the
        state is then stepped in place. From one measured orientation `(4, 1)` it allocates
        nothing of size K, unless some (not all) DMPs are locked; orientations `(4, K)` are
        checked and normalised into a new array first."""
        orientations = np.asarray(orientations, dtype=float)
        if orientations.size not in (4, 4 * self.goal_count):
            raise ValueError(f"orientations must be (4, 1) or (4, {self.goal_count}), got shape "
                             f"{orientations.shape}")
        orientations = quaternion.unit_quaternions(orientations.reshape(4, -1).T,
                                                   "orientations").T
        if locked is not None:
            locked = np.broadcast_to(np.asarray(locked, bool), np.shape(phase))
        if locked is None or not locked.any():
            self._step_into(phase, orientations, scaled_angular_velocity, goals_4k, dt,
                            out_phase, out_orientations, out_velocity, workspace)
            return
        held = (scaled_angular_velocity if robot_angular_velocity is None else
                np.broadcast_to(self.duration * np.asarray(
                    robot_angular_velocity, float).reshape(AXES, 1), out_velocity.shape))
        if locked.all():
            out_phase[...] = phase
            out_orientations[...] = orientations
            out_velocity[...] = held
            return
        # Some locked, some not: the free step into temporaries, then chosen (rare).
        stepped = (np.empty_like(out_phase), np.empty_like(out_orientations),
                   np.empty_like(out_velocity))
        self._step_into(phase, orientations, scaled_angular_velocity, goals_4k, dt, *stepped,
                        workspace)
        out_phase[...] = np.where(locked, phase, stepped[0])
        out_orientations[...] = np.where(locked, orientations, stepped[1])
        out_velocity[...] = np.where(locked, held, stepped[2])

    def _start_errors_into(self, goals_4k, workspace, goals_unchanged=False):
        """`e0 = Log(q0 g*)` into `workspace.start_errors`, and the Ijspeert amplitude `-e0`
        (1 where the fit switched the scaling off) into `workspace.amplitude`."""
        if (workspace.starts_of_start_errors is self.starts
                and (goals_unchanged
                     or np.array_equal(workspace.goals_of_start_errors, goals_4k))):
            return  # the goals did not change: one pass instead of a log map
        starts = self._uniform_start if self._uniform_start is not None else self.starts
        error_quaternions_into(starts, goals_4k, workspace.error_quaternions, workspace.row)
        log_into(workspace.error_quaternions, workspace.start_errors, workspace)
        if self._ijspeert:
            np.negative(workspace.start_errors, out=workspace.amplitude)
            if not self._all_scaled:
                np.copyto(workspace.amplitude, 1.0, where=~self.amplitude_scaling)
        workspace.goals_of_start_errors[...] = goals_4k
        workspace.starts_of_start_errors = self.starts
        if workspace.scaled_rows is not None:
            workspace.scaled_rows[...] = False  # they were multiplied by the old `-e0`

    def _step_into(self, phase, orientations, velocity, goals_4k, dt, out_phase,
                   out_orientations, out_velocity, workspace):
        """The free step (see `pbp_drake.core.dmp.orientation`), vectorised over K:
        `log_step_into`, then `orientations_from_log_into`."""
        ws = workspace
        self.log_step_into(phase, orientations, velocity, goals_4k, dt, out_phase,
                           ws.new_log_state, ws)
        self.orientations_from_log_into(ws.new_errors, ws.new_log_velocity, goals_4k,
                                        orientations, out_orientations, out_velocity, ws)

    def log_step_into(self, phase, orientations, velocity, goals_4k, dt, out_phase,
                      out_log_state, workspace, goals_unchanged=False, basis=None):
        """The free step in log coordinates: `e = Log(q g*)` and `z = J(e)^-1 eta` from the
        measured orientations `(4, 1)` or `(4, K)` (unit) and `eta` `(3, K)` or `(3, 1)`
        (one for all: PBP's goal switch), stepped as the position bank steps `(y, z)`:
        `(e', z')` into `out_log_state` (2, 3, K), the phases into `out_phase` (Drake's
        pose bank keeps `(e', z')` and reads the orientations out on demand).
        `goals_unchanged=True` vouches that `goals_4k` holds the goals of this workspace's
        last step: the start errors are then reused without comparing the goals. `basis`:
        the step's combined basis `(2, N)` and `lambda` `(2, 1)` when the caller has them
        already (a position bank of the same settings and duration stepped at the same
        phase: its workspace's `basis` and `lam`), used with distinct Ijspeert weights at
        equal phases."""
        ws = workspace
        constants = step_constants(self._settings.stiffness, self._settings.damping,
                                   self.duration, dt)
        decay = self.decay(dt)
        self._start_errors_into(goals_4k, ws, goals_unchanged)
        # [e'; z'] = (Phi (x) I3) [e; z] + [b; b'] (the position bank's step, goal 0).
        if orientations.shape[1] == 1 and velocity.shape[1] == 1:
            # One orientation and one velocity for all: fused, `b` within
            # (`orientation_log_step`).
            # Distinct Ijspeert weights: `b` contracted straight into the output, to which
            # the step adds the rest (`forcing` None); else `b` in the fused rows.
            into = out_log_state if out_log_state.flags.c_contiguous else ws.shape
            lam = self._scaled_forcing(phase, decay, constants.combination, ws, basis, into)
            if lam is None:
                shapes, lam = self._combined_shapes(phase, decay, constants.combination, ws)
                forcing = forcing_rows(shapes, lam, self._ijspeert, ws)
            else:
                forcing = None if into is out_log_state else IDENTITY6
            phi = ((1.0 + constants.position_offset, constants.position_velocity),
                   (constants.velocity_offset, constants.velocity_velocity))
            log_step_from_one_into(orientations, velocity, goals_4k, phi, forcing,
                                   out_log_state, ws)
        else:
            shapes, lam = self._combined_shapes(phase, decay, constants.combination, ws)
            error_quaternions_into(orientations, goals_4k, ws.error_quaternions, ws.row)
            log_into(ws.error_quaternions, ws.errors, ws)
            inverse_jacobian_into(ws.errors, velocity, ws.log_velocity, ws)
            np.dot(_log_transition(*constants[:4]), ws.log_state.reshape(2 * AXES, -1),
                   out=out_log_state.reshape(2 * AXES, -1))
            if self._ijspeert:
                # b = S (-e0) (S alone where the fit switched the scaling off).
                np.multiply(shapes, ws.amplitude, out=ws.shape)
            else:
                # b = S + lambda e0 (`shapes` may be `ws.shape` itself: added first).
                out_log_state += shapes
                np.multiply(ws.start_errors, lam[:, np.newaxis, :], out=ws.shape)
            out_log_state += ws.shape
        np.multiply(phase, decay, out=out_phase)

    def orientations_from_log_into(self, errors, log_velocity, goals_4k, reference,
                                   out_orientations, out_velocity, workspace):
        """`q = Exp(e) g` (4, K), signed as `reference` (4, 1) or (4, K) so that a stream
        stays continuous, and `eta = J(e) z` (3, K), from log coordinates `(e, z)`
        (`log_step_into`'s outputs may be the inputs here, not the outputs)."""
        ws = workspace
        turned = ws.error_quaternions  # Exp(e'), then q' = Exp(e') g
        exp_into(errors, turned, ws)
        jacobian_into(errors, log_velocity, out_velocity, ws)
        product_into(turned, goals_4k, ws.product, ws.row)
        if reference.shape[1] == 1:
            np.dot(reference[:, 0], ws.product, out=ws.row)
        else:
            np.multiply(ws.product, reference, out=turned)
            np.sum(turned, axis=0, out=ws.row)
        np.less(ws.row, 0.0, out=ws.small)
        np.multiply(ws.small, -2.0, out=ws.row)  # -1 where the sign flips, else +1
        ws.row += 1.0
        np.multiply(ws.product, ws.row, out=out_orientations)

    def _add_relative_attractor(self, target, shape, lam, workspace):
        """`target += b`, a combination of attractors: Ijspeert `S (-e0)` (S alone where
        the scaling is off), Pastor `S + lambda e0`."""
        if self._ijspeert:
            np.multiply(shape, workspace.amplitude, out=workspace.work)
        else:
            target += shape
            np.multiply(workspace.start_errors, lam, out=workspace.work)
        target += workspace.work

    def _equal_phase_basis(self, phase, decay, combination):
        """Equal phases: the basis at the step's two phases only, combined, `(2, N)`, and
        `lambda` `(2, 1)` (see `_combined_shapes`)."""
        scale = 1.0 / self._settings.stiffness if self._ijspeert else 1.0
        phases = np.array([phase.flat[0], phase.flat[0] * decay])
        scaled = normalized_basis(phases, self._centres, self._widths) * (phases * scale)
        return combination @ scaled.T, (combination @ phases)[:, np.newaxis]

    def _scaled_forcing(self, phase, decay, combination, workspace, basis=None, out=None):
        """Ijspeert, distinct weights and equal phases: `b = S (-e0)` straight into `out`
        (2, 3, K) (default: the workspace's `shape`), from the weights already multiplied
        by `-e0` (`contraction.scaled_weights`: the rows that matter, kept while the goals
        stay), so no pass multiplies `S`; the start errors must be the goals'. `basis`:
        `(basis, lambda)` computed by the caller, else here. Returns `lambda`, or None in
        any other case."""
        if (not self._ijspeert or self.shared_weights
                or (phase.size > 1 and phase.min() != phase.max())):
            return None
        basis, lam = (self._equal_phase_basis(phase, decay, combination) if basis is None
                      else basis)
        window = self._weight_rows.window(basis)
        weights = scaled_weights(self._weight_rows.weights, workspace, *window)
        out = workspace.shape if out is None else out
        self._weight_rows.contract_into(basis, out.reshape(2, -1), weights, window)
        return lam

    def _combined_shapes(self, phase, decay, combination, workspace):
        """Rows r of `combination` (2x2): `S_r = C_r0 s(x0) + C_r1 s(x1)` with
        `s(x) = (psi.w / sum psi) x` (over K in the Ijspeert form), `(2, 3, 1)` or
        `(2, 3, K)`, and `lambda_r = C_r0 x0 + C_r1 x1`, `(2, 1)` or `(2, K)`."""
        scale = 1.0 / self._settings.stiffness if self._ijspeert else 1.0
        if phase.size == 1 or phase.min() == phase.max():
            basis, lam = self._equal_phase_basis(phase, decay, combination)
            if self.shared_weights:
                return (basis @ self._weights)[:, :, np.newaxis], lam
            self._weight_rows.contract_into(basis, workspace.shape.reshape(2, -1))
            return workspace.shape, lam
        # A phase per goal: (N, 2, K) bases (allocates).
        phases = np.stack([phase, phase * decay])
        scaled = normalized_basis(phases, self._centres, self._widths) * (phases * scale)
        combined = np.einsum("rs,nsk->rnk", combination, scaled)  # (2, N, K)
        if self.shared_weights:
            shapes = np.einsum("nd,rnk->rdk", self._weights, combined)
        else:
            shapes = np.einsum("ndk,rnk->rdk", self._weights, combined)
        return shapes, combination @ phases
