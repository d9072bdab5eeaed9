"""The step of a `DmpBankModel`: K DMPs advanced one first-order-hold step, vectorised over (D, K).

With `(Phi, Gamma)` of `settings.step_matrices`, the attractor `a0` at the step's phase and
`a1` at the next, `e = y - a0` and `da = a1 - a0`, the step (docs/concepts/dmp.md, "One
step, in closed form") is affine in the DMP's own velocity `z`:

    y' = y + dp + Phi01 z,    z' = dz + Phi11 z,
    dp = (Phi00 - 1) e + (1 - Gamma00 / dt) da,    dz = Phi10 e - (Gamma10 / dt) da.

PBP steps from the robot's position `y = p`, so `(dp, dz)`, "the attractor terms", depend
on the phase, `p`, the goals and `dt` only (`attractor_terms_into`); `stepped_positions_into`
and `stepped_velocity_into` add the velocity's part.

Writing `b(x) = a(x) - g` (the attractor relative to the goal),

    dp = (Phi00 - 1)(p - g) + C00 b(x0) + C01 b(x1),
    dz = Phi10 (p - g) + C10 b(x0) + C11 b(x1),

with the 2x2 `C` of `StepConstants.combination`; `b` is linear in the normalised basis, so
the weights are contracted once with both rows' combinations of the bases at `x0` and `x1`."""

import functools
import math
from typing import NamedTuple

import numpy as np

from pbp_drake.core.dmp._checks import read_only
from pbp_drake.core.dmp.contraction import WeightRows, scaled_weights
from pbp_drake.core.dmp.settings import normalized_basis, step_matrices

_IDENTITY = np.eye(2)
_IDENTITY.setflags(write=False)


class StepConstants(NamedTuple):
    """The numbers of one step of `dt` (see the module docstring), shared by every DMP.

    Attributes:
        position_offset, position_velocity: `Phi00 - 1`, `Phi01`.
        velocity_offset, velocity_velocity: `Phi10`, `Phi11`.
        offset_gains: (2, 1, 1) read-only, `[Phi00 - 1, Phi10]`.
        combination: (2, 2) read-only `C`:
            `[[Gamma00 / dt - Phi00, 1 - Gamma00 / dt], [Gamma10 / dt - Phi10, -Gamma10 / dt]]`.
    """

    position_offset: float
    position_velocity: float
    velocity_offset: float
    velocity_velocity: float
    offset_gains: np.ndarray
    combination: np.ndarray


@functools.lru_cache(maxsize=256)
def step_constants(stiffness, damping, duration, dt):
    """The memoised `StepConstants` of one step (keyed on plain floats, as `step_matrices`)."""
    phi, gamma = step_matrices(stiffness, damping, duration, dt)
    g0, g1 = gamma[0, 0] / dt, gamma[1, 0] / dt
    combination = np.array([[g0 - phi[0, 0], 1.0 - g0], [g1 - phi[1, 0], -g1]])
    gains = np.array([phi[0, 0] - 1.0, phi[1, 0]]).reshape(2, 1, 1)
    combination.setflags(write=False)
    gains.setflags(write=False)
    return StepConstants(float(phi[0, 0] - 1.0), float(phi[0, 1]), float(phi[1, 0]),
                         float(phi[1, 1]), gains, combination)


class BankStep:
    """The stepping half of `pbp_drake.core.dmp.DmpBankModel`, mixed into it.

    Reads the model `DmpBankModel.__init__` sets (`_settings`, `duration`, `starts`,
    `amplitude_scaling`, `_weights`, `shared_weights`, `_centres`, `_widths`) and the
    constants `_derive_constants` adds; writes only into arrays its callers pass.
    """

    def _derive_constants(self):
        """Per-bank constants of the step, computed once (read-only)."""
        self._negative_widths = read_only(-self._widths, float)
        self._ijspeert = self._settings.formulation == "ijspeert"
        self._stiffness = self._settings.stiffness
        self._damping = self._settings.damping
        self._unscaled = ~self.amplitude_scaling
        self._unscaled.setflags(write=False)
        self._all_scaled = not self._unscaled.any()
        # Shared weights, a per-dimension amplitude scaling and one start: with equal phases
        # the attractor terms are `alpha g + beta` per dimension (see `_affine_terms_into`).
        scaling, starts = self.amplitude_scaling, self.starts
        self._affine_in_goal = (
            self.shared_weights and bool((scaling.all(axis=1) | ~scaling.any(axis=1)).all())
            and bool((starts == starts[:, :1]).all()))
        self._uniform_start = read_only(starts[:, :1], float)
        self._weight_rows = (None if self.shared_weights else WeightRows(
            self._weights.reshape(self._settings.basis_count, -1)))
        # b = S (sigma g + rho) for Ijspeert (S the shape; sigma 1 where scaled, and
        # rho = 1 - sigma (1 + y0)); b = S - lambda (g - y0) for Pastor.
        sigma = scaling[:, :1].astype(float)
        self._goal_weight = read_only(sigma if self._ijspeert else np.zeros_like(sigma), float)
        self._shape_weight = read_only(
            1.0 - sigma * (1.0 + starts[:, :1]) if self._ijspeert else np.ones_like(sigma), float)

    def step_constants(self, dt):
        """The `StepConstants` of one step of `dt` (memoised)."""
        return step_constants(self._stiffness, self._damping, self.duration, dt)

    def attractors(self, phase, goals_dk):
        """The moving attractors `(D, K)` for phases `(K,)` and goals `(D, K)`, a new array."""
        workspace = self.make_workspace()
        shapes, lam = self._combined_shapes(np.asarray(phase, dtype=float), 1.0, _IDENTITY,
                                            workspace)
        attractor = np.array(goals_dk, dtype=float)
        self._add_relative_attractor(attractor, shapes[0], lam[0],
                                     self._amplitudes(goals_dk, workspace), workspace.shape[0])
        return attractor

    def attractor_terms_into(self, phase, positions, goals_dk, dt, out_dp, out_dz, workspace,
                             goals_unchanged=False):
        """The attractor terms `(dp, dz)` (D, K) of the step from `positions` (D, K) or
        (D, 1) at phases `phase` (K,) towards `goals_dk`, into `out_dp` and `out_dz` (the
        caller's, or the workspace's `dp` and `dz`; the other work arrays are used).
        `goals_unchanged=True` vouches that `goals_dk` holds the goals of this workspace's
        last call: with distinct weights (Ijspeert, equal phases) the step then contracts the
        weights already multiplied by `g - y0` (`contraction.scaled_weights`)."""
        constants = self.step_constants(dt)
        equal = phase.size == 1 or phase.min() == phase.max()
        if (goals_unchanged and equal and self._ijspeert and not self.shared_weights
                and workspace.scaled_rows is not None):
            self._scaled_terms_into(phase, positions, goals_dk, constants, self.decay(dt),
                                    out_dp, out_dz, workspace)
            return
        if workspace.scaled_rows is not None:
            workspace.scaled_rows[...] = False  # the amplitudes below may be new goals'
        elif goals_unchanged and self._ijspeert and not self.shared_weights:
            workspace.scaled_rows = np.zeros(0, bool)  # the next call may take them
        shapes, lam = self._combined_shapes(phase, self.decay(dt), constants.combination,
                                            workspace, equal)
        if self._affine_in_goal and equal:
            self._affine_terms_into(shapes, lam, positions, goals_dk, constants, out_dp,
                                    out_dz, workspace)
            return
        amplitudes = self._amplitudes(goals_dk, workspace)
        relative = workspace.work
        np.subtract(positions, goals_dk, out=relative)  # p - g
        for row, out, gain in ((0, out_dp, constants.position_offset),
                               (1, out_dz, constants.velocity_offset)):
            np.multiply(relative, gain, out=out)
            self._add_relative_attractor(out, shapes[row], lam[row], amplitudes,
                                         workspace.shape[row])

    def stepped_from_one_into(self, phase, position, scaled_velocity, goals_dk, dt, out,
                              workspace, goals_unchanged=False):
        """The step of every DMP from ONE measured position `position` (D, 1) and the scaled
        velocities `z` (D, 1: one for all, PBP's goal switch; or D, K): `out[0] = y' - p =
        dp + Phi01 z` and `out[1] = z' = dz + Phi11 z` (`out` (2, D, K)), what Drake's pose
        bank keeps. `goals_unchanged` as `attractor_terms_into`. With equal phases the step's
        combined basis and `lambda` are left in `workspace.basis` and `workspace.lam` (an
        orientation bank of the same settings steps with them: `log_step_into`'s `basis`).
        With weights kept multiplied by the amplitudes and one `z`, the weights are
        contracted straight into `out`, then `-(Phi00 - 1, Phi10) g` (kept while the goals
        stay) and one column, `(Phi00 - 1, Phi10) p + (Phi01, Phi11) z`, are added."""
        constants = self.step_constants(dt)
        ws = workspace
        if (goals_unchanged and scaled_velocity.shape[1] == 1 and self._ijspeert
                and not self.shared_weights and ws.scaled_rows is not None
                and (phase.size == 1 or phase.min() == phase.max())):
            self._scaled_shapes_into(phase, self.decay(dt), constants, ws, out)
            if ws.goal_terms is None or ws.goal_terms_dt != dt:
                ws.goal_terms = np.multiply(constants.offset_gains, goals_dk)
                np.negative(ws.goal_terms, out=ws.goal_terms)
                ws.goal_terms_dt = dt
            out += ws.goal_terms
            # The column in floats, the same products and sums as NumPy's (a NumPy call
            # costs more than six numbers' arithmetic).
            p, z = position[:, 0].tolist(), scaled_velocity[:, 0].tolist()
            ws.column[:, :, 0] = [
                [constants.position_offset * a + constants.position_velocity * b
                 for a, b in zip(p, z)],
                [constants.velocity_offset * a + constants.velocity_velocity * b
                 for a, b in zip(p, z)]]
            out += ws.column
            return
        self.attractor_terms_into(phase, position, goals_dk, dt, out[0], out[1], ws,
                                  goals_unchanged)
        ws.goal_terms = None  # the next fast step recomputes them (the goals may be new)
        velocity_part = ws.column[0] if scaled_velocity.shape[1] == 1 else ws.work
        np.multiply(scaled_velocity, constants.position_velocity, out=velocity_part)
        out[0] += velocity_part
        np.multiply(scaled_velocity, constants.velocity_velocity, out=velocity_part)
        out[1] += velocity_part

    def _scaled_shapes_into(self, phase, decay, constants, workspace, out):
        """`S (g - y0)` (2, D, K) into `out`: the step's combined basis at equal phases
        (left in the workspace's `basis` and `lam`) contracted with the weights kept
        multiplied by the amplitudes, over the rows that matter."""
        ws = workspace
        self._combined_shapes(phase, decay, constants.combination, ws, True, basis_only=True)
        window = self._weight_rows.window(ws.basis)
        weights = scaled_weights(self._weight_rows.weights, ws, *window)
        self._weight_rows.contract_into(ws.basis, out.reshape(2, -1), weights, window)

    def _scaled_terms_into(self, phase, positions, goals_dk, constants, decay, out_dp, out_dz,
                           workspace):
        """`attractor_terms_into` with distinct weights times the amplitudes `g - y0` of
        the workspace's last goals (the same goals): `b = S (g - y0)` from the contraction,
        then `dp = (Phi00 - 1)(p - g) + b0`, `dz = Phi10 (p - g) + b1`."""
        ws = workspace
        self._scaled_shapes_into(phase, decay, constants, ws, ws.shape)
        np.subtract(positions, goals_dk, out=out_dz)  # p - g
        np.multiply(out_dz, constants.position_offset, out=out_dp)
        out_dp += ws.shape[0]
        out_dz *= constants.velocity_offset
        out_dz += ws.shape[1]

    def stepped_positions_into(self, positions, dp, scaled_velocity, dt, out, workspace):
        """`out = positions + dp + Phi01 z`: the positions after the step (`out` may be
        `positions`; `workspace.work` holds `Phi01 z`)."""
        work = workspace.work
        np.multiply(scaled_velocity, self.step_constants(dt).position_velocity, out=work)
        np.add(positions, dp, out=out)
        out += work
        return out

    def stepped_velocity_into(self, dz, scaled_velocity, dt, out):
        """`out = dz + Phi11 z`: the scaled velocities after the step (`out` may be
        `scaled_velocity`, not `dz`). Two passes, no scratch."""
        np.multiply(scaled_velocity, self.step_constants(dt).velocity_velocity, out=out)
        out += dz
        return out

    def _amplitudes(self, goals_dk, workspace):
        """`g - y0` into `workspace.amplitude`, 1 where the Ijspeert scaling is off."""
        amplitude = workspace.amplitude
        np.subtract(goals_dk, self.starts, out=amplitude)
        if self._ijspeert and not self._all_scaled:
            np.copyto(amplitude, 1.0, where=self._unscaled)
        return amplitude

    def _add_relative_attractor(self, out, shape, lam, amplitudes, scratch):
        """`out += b`, one row's combination of the relative attractors `b = a - g`:
        `shape * amplitude` (Ijspeert) or `shape - amplitude * lambda` (Pastor). `scratch`
        is `(D, K)` and may be `shape`."""
        if self._ijspeert:
            np.multiply(shape, amplitudes, out=scratch)
            out += scratch
        else:
            out += shape
            np.multiply(amplitudes, lam, out=scratch)
            out -= scratch

    def _combined_shapes(self, phase, decay, combination, workspace, equal=None,
                         basis_only=False):
        """For the rows r of `combination` (2x2): the forcing shapes
        `S_r = C_r0 s(x0) + C_r1 s(x1)`, `s(x) = (psi.w / sum psi) x` (divided by K in the
        Ijspeert form), `(2, D, 1)` (shared weights, equal phases) or `(2, D, K)`, and
        `lambda_r = C_r0 x0 + C_r1 x1`, `(2, 1)` or `(2, K)`, with `x1 = x0 decay`."""
        if equal is None:
            equal = phase.size == 1 or phase.min() == phase.max()
        if equal:
            phases, psi, scale = workspace.phases, workspace.psi, workspace.scale
            phases[0, 0] = phase.flat[0]
            phases[1, 0] = phases[0, 0] * decay
            np.subtract(phases, self._centres, out=psi)
            np.square(psi, out=psi)
            psi *= self._negative_widths
            np.exp(psi, out=psi)
            np.add.reduce(psi, axis=1, keepdims=True, out=scale)  # np.sum, without its wrapper
            np.divide(phases, scale, out=scale)
            if self._ijspeert:
                scale /= self._stiffness
            psi *= scale
            np.dot(combination, psi, out=workspace.basis)
            np.dot(combination, phases, out=workspace.lam)
            if basis_only:
                return None
            if self.shared_weights:
                np.dot(workspace.basis, self._weights, out=workspace.coefficients)
                return workspace.coefficients[:, :, np.newaxis], workspace.lam
            self._weight_rows.contract_into(workspace.basis, workspace.shape.reshape(2, -1))
            return workspace.shape, workspace.lam
        # A phase per goal: K bases at each end of the step.
        phases = np.stack([phase, phase * decay])  # (2, K)
        scaled = [normalized_basis(x, self._centres, self._widths) * x for x in phases]
        if self._ijspeert:
            scaled = [basis / self._stiffness for basis in scaled]
        shapes = workspace.shape
        for row in range(2):
            combined = combination[row, 0] * scaled[0] + combination[row, 1] * scaled[1]
            if self.shared_weights:
                np.matmul(self._weights.T, combined, out=shapes[row])
            else:
                np.einsum("nk,ndk->dk", combined, self._weights, out=shapes[row])
        return shapes, combination @ phases

    @property
    def affine_in_goal(self):
        """True when the DMPs share weights and start (and each dimension's amplitude
        scaling): at one phase, the step's attractor terms are then `alpha g + beta` with
        per-dimension coefficients (`affine_coefficients`)."""
        return self._affine_in_goal

    def affine_coefficients(self, phase, position, dt, workspace):
        """`(alpha, beta)`, each `(2, D, 1)` (views into `workspace`): the attractor terms of
        the step of `dt` from ONE position `position` (D, 1) at the one phase `phase` are
        `dp = alpha[0] g + beta[0]` and `dz = alpha[1] g + beta[1]` for every goal `g`,
        computed as `attractor_terms_into` computes them (the same numbers, bit for bit).
        Only for a bank `affine_in_goal`."""
        if not self._affine_in_goal:
            raise ValueError("affine_coefficients needs DMPs that share weights and start")
        constants = self.step_constants(dt)
        shapes, lam = self._combined_shapes(np.asarray(phase, dtype=float), self.decay(dt),
                                            constants.combination, workspace, True)
        return self._affine_coefficients_into(shapes, lam, position, constants, workspace)

    def _affine_coefficients_into(self, shapes, lam, positions, constants, workspace):
        """`alpha` and `beta` of `_affine_terms_into` (with `positions` (D, 1), its `p`
        part in `beta`) in the workspace's arrays."""
        gains, alpha, beta = constants.offset_gains, workspace.alpha, workspace.beta
        column = workspace.column
        # term = gain (p - g) + S (sigma g + rho) [Ijspeert] or + S - lambda (g - y0) [Pastor]
        np.multiply(shapes, self._goal_weight, out=alpha)
        alpha -= gains
        np.multiply(shapes, self._shape_weight, out=beta)
        if not self._ijspeert:
            lam = lam[:, :, np.newaxis]
            alpha -= lam
            np.multiply(lam, self._uniform_start, out=column)
            beta += column
        if positions.shape[1] == 1:
            np.multiply(gains, positions, out=column)
            beta += column
        return alpha, beta

    def _affine_terms_into(self, shapes, lam, positions, goals_dk, constants, out_dp, out_dz,
                           workspace):
        """Shared weights, one phase and one start: each row's term is `alpha g + beta`
        with `(D, 1)` coefficients, two passes over `(D, K)` per row."""
        gains = constants.offset_gains
        alpha, beta = self._affine_coefficients_into(shapes, lam, positions, constants,
                                                     workspace)
        single = positions.shape[1] == 1
        for row, out in ((0, out_dp), (1, out_dz)):
            np.multiply(goals_dk, alpha[row], out=out)
            out += beta[row]
            if not single:
                np.multiply(positions, gains[row, 0, 0], out=workspace.work)
                out += workspace.work


def limit_speeds(scaled_velocities, max_speed, duration):
    """Scales each column of the scaled velocities `tau v` (D, K) down to the speed
    `max_speed` (None: no limit), in place: the systems' anti-windup (why:
    docs/concepts/dmp.md, "PBP: re-integrating from the robot every step")."""
    if max_speed is None:
        return
    if scaled_velocities.shape[1] == 1:
        # One column (every tick with a followed goal): plain floats, a fifth of the time,
        # summed one after another as NumPy's norm sums a short column (not with `sum`,
        # which compensates its rounding from Python 3.12 on).
        squares = 0.0
        for value in scaled_velocities[:, 0].tolist():
            squares += value * value
        speed = math.sqrt(squares) / duration
        if speed > max_speed:
            scaled_velocities *= max_speed / speed
        return
    speeds = np.linalg.norm(scaled_velocities, axis=0) / duration
    too_fast = speeds > max_speed
    if np.any(too_fast):
        scaled_velocities[:, too_fast] *= max_speed / speeds[too_fast]
