"""The two state layouts of Drake's `DmpBank` system: what its discrete state holds, how an
update writes it, and how the DMPs' stepped states are read out of it.

The step is affine in the DMP's velocity `z` (`p' = p + dp + Phi01 z`, `z' = dz + Phi11 z`;
`pbp_drake.core.dmp.stepping`), so a layout keeps `z` before the step and the step's
attractor terms `dp`, `dz`. While `held` the DMPs sit at `p + dp` with velocity `z`.

- `PerGoalState`, `[phase, held, p (D), z, dp, dz (D, K each)]`: any bank.
- `AffineState`, `[phase, held, p (D), z (D), alpha (2 D), beta (2 D)]`: a bank
  `affine_in_goal` stepped from the followed DMP's velocity, where `dp = alpha[0] g +
  beta[0]`, `dz = alpha[1] g + beta[1]` for each goal `g`; its numbers are the per-goal
  layout's bit for bit (the same operations in the same order; docs/concepts/dmp.md).
"""

import numpy as np

from pbp_drake.core.dmp.stepping import limit_speeds


class _Layout:
    """What both layouts share: the state vector starts `[phase, held, ...]`."""

    def __init__(self, bank, period, max_speed):
        self._bank, self._period, self._max_speed = bank, period, max_speed
        self.size = self.size_of(bank.goal_count, bank.dimension)

    def initial(self):
        """Held at the start, phase 1, the rest as `_at_start` sets it."""
        vector = np.zeros(self.size)
        vector[0:2] = 1.0
        self._at_start(vector)
        return vector

    def phase(self, vector):
        return vector[0]


class PerGoalState(_Layout):
    """Every DMP's `z`, `dp` and `dz` in the state (see the module docstring)."""

    def __init__(self, bank, period, max_speed):
        super().__init__(bank, period, max_speed)
        self.needs_followed_goal = False
        self.reads = None  # the read-out depends on the state alone

    @staticmethod
    def size_of(goal_count, dimension):
        return 2 + dimension + 3 * goal_count * dimension

    def _split(self, vector):
        """Views: phase (1,), held (1,), p (D, 1), z, dp and dz (D, K)."""
        d, k = self._bank.dimension, self._bank.goal_count
        z, dp, dz = (2 + d + i * k * d for i in range(3))
        return (vector[0:1], vector[1:2], vector[2:2 + d].reshape(d, 1),
                vector[z:dp].reshape(d, k), vector[dp:dz].reshape(d, k),
                vector[dz:dz + k * d].reshape(d, k))

    def _at_start(self, vector):
        """The DMPs sit at their starts (p = 0, dp = starts), at rest."""
        self._split(vector)[4][...] = self._bank.starts

    def update(self, vector, robot_state, lock, goals_dk, followed, workspace):
        """One update, in place (`goals_dk` may be None when `lock`)."""
        bank, period = self._bank, self._period
        d = bank.dimension
        phase, held, robot, z, dp, dz = self._split(vector)
        # The velocities the last step left, read out in place.
        if not held[0]:
            bank.stepped_velocity_into(dz, z, period, z)
            if followed is not None:
                # PBP's goal switch (`DmpBankModel.advance`'s `followed`).
                z[...] = z[:, followed:followed + 1]
            limit_speeds(z, self._max_speed, bank.duration)
        robot[:, 0] = robot_state[:d]
        if lock:
            # Phases frozen: the DMPs stay at the robot's position and follow its velocity.
            held[0] = 1.0
            dp.fill(0.0)
            np.multiply(robot_state[d:, np.newaxis], bank.duration, out=z)
            return
        held[0] = 0.0
        bank.attractor_terms_into(phase, robot, goals_dk, period, dp, dz, workspace)
        phase *= bank.decay(period)

    def read(self, vector, given, workspace, goal=None):
        """The stepped positions and scaled velocities `(D, K)` of every DMP, or `(D, 1)`
        of DMP `goal`, new arrays (`given`: what the layout `reads`, here nothing)."""
        _, held, robot, z, dp, dz = self._split(vector)
        if goal is not None:
            z, dp, dz = (array[:, goal:goal + 1] for array in (z, dp, dz))
        positions = np.add(robot, dp)
        if held[0]:
            return positions, np.array(z)
        work = np.multiply(z, self._bank.step_constants(self._period).position_velocity,
                           out=workspace.work if goal is None else None)
        positions += work
        return positions, self._bank.stepped_velocity_into(dz, z, self._period,
                                                           np.empty(z.shape))


class AffineState(_Layout):
    """One `z` and the attractor terms' per-dimension coefficients in the state (see the
    module docstring)."""

    def __init__(self, bank, period, max_speed):
        super().__init__(bank, period, max_speed)
        self.needs_followed_goal = True
        self.reads = "goals"  # the read-out evaluates the attractor terms at the goals

    @staticmethod
    def size_of(goal_count, dimension):
        return 2 + 6 * dimension  # whatever K

    def _split(self, vector):
        """Views: phase (1,), held (1,), p (D, 1), z (D, 1), alpha and beta (2, D, 1)."""
        d = self._bank.dimension
        return (vector[0:1], vector[1:2], vector[2:2 + d].reshape(d, 1),
                vector[2 + d:2 + 2 * d].reshape(d, 1),
                vector[2 + 2 * d:2 + 4 * d].reshape(2, d, 1),
                vector[2 + 4 * d:2 + 6 * d].reshape(2, d, 1))

    def _at_start(self, vector):
        """At rest at the (one) start: dp = 0 g + start."""
        self._split(vector)[5][0] = self._bank.starts[:, :1]

    def update(self, vector, robot_state, lock, goals_dk, followed, workspace):
        """One update, in place: the per-goal layout's arithmetic on the followed DMP."""
        bank, period = self._bank, self._period
        d = bank.dimension
        phase, held, robot, z, alpha, beta = self._split(vector)
        robot[:, 0] = robot_state[:d]
        if lock:
            # Phases frozen: the DMPs stay at the robot's position (dp = 0 g + 0).
            held[0] = 1.0
            alpha.fill(0.0)
            beta.fill(0.0)
            np.multiply(robot_state[d:, np.newaxis], bank.duration, out=z)
            return
        if not held[0]:
            # The followed DMP's velocity after the last step: dz + Phi11 z, its dz from
            # the last step's coefficients at its goal.
            dz = np.multiply(goals_dk[:, followed:followed + 1], alpha[1])
            dz += beta[1]
            bank.stepped_velocity_into(dz, z, period, z)
            limit_speeds(z, self._max_speed, bank.duration)
        held[0] = 0.0
        # `robot` is the state's copy: the coefficients' `p` part reads it.
        new_alpha, new_beta = bank.affine_coefficients(phase, robot, period, workspace)
        alpha[...] = new_alpha
        beta[...] = new_beta
        phase *= bank.decay(period)

    def read(self, vector, given, workspace, goal=None):
        """As `PerGoalState.read`, at the goals `given` (D, K) on the port."""
        goals_dk = given
        _, held, robot, z, alpha, beta = self._split(vector)
        goals = goals_dk if goal is None else goals_dk[:, goal:goal + 1]
        positions = np.multiply(goals, alpha[0])
        positions += beta[0]  # dp
        positions += robot  # p + dp (p + dp in the per-goal layout: the same sum)
        if held[0]:
            return positions, np.repeat(z, goals.shape[1], axis=1)
        positions += z * self._bank.step_constants(self._period).position_velocity
        velocity = np.multiply(goals, alpha[1])
        velocity += beta[1]  # dz
        # dz + Phi11 z, summed as the per-goal layout sums Phi11 z + dz.
        velocity += z * self._bank.step_constants(self._period).velocity_velocity
        return positions, velocity
