"""K DMPs, one per goal, as one immutable model stepped by pure and in-place functions.

The model is fixed at construction (read-only arrays; assigning an attribute raises); the
state of the DMPs is passed in and out of every call, and the in-place step's scratch lives
in a `DmpWorkspace` the caller owns (`make_workspace`). So one bank may serve any number of
threads, Drake Contexts or Simulators at once."""

import dataclasses

import numpy as np

from pbp_drake.core.coordinates import check_positions, is_whole
from pbp_drake.core.dmp._checks import (
    as_point, broadcast_goalwise, dmp_settings, followed_velocity, goal_count_of, goal_indices,
    positive, read_only)
from pbp_drake.core.dmp.fitting import fit_weights, validate_demonstration
from pbp_drake.core.dmp.settings import DmpSettings, phase_decay
from pbp_drake.core.dmp.single import straight_weights
from pbp_drake.core.dmp.stepping import BankStep
from pbp_drake.core.dmp.workspace import DmpWorkspace


class BankModel:
    """What the position bank and `OrientationDmpBank` share: the model's checks
    (`_keep_model`), immutability after `__init__`, the settings, the phase decay, the
    constructors from single DMPs and of straight paths, and open-loop prediction (a
    subclass keeps its `starts` as `(rows, K)`)."""

    def __setattr__(self, name, value):
        if getattr(self, "_frozen", False):
            raise AttributeError(f"{type(self).__name__} is immutable: cannot set {name!r}")
        object.__setattr__(self, name, value)

    def _keep_model(self, weights, starts, duration, settings, amplitude_scaling, goal_count,
                    dimension):
        """Checks and keeps what every bank's `__init__` does: a private copy of `settings`
        (a plain dataclass the caller may change later), `duration`, the weights, read-only
        (`(N, D)` shared by all goals, or `(K, N, D)` one set per goal, kept `(N, D, K)`),
        `goal_count` (K: with shared weights the given one, else one per row of `starts`),
        `dimension` (D; None: the weights'), the amplitude scaling `(D, K)` and the basis."""
        dmp_settings(settings).validate()
        self._settings = dataclasses.replace(settings)
        self.duration = positive(duration, "duration")
        weights = np.asarray(weights, dtype=float)
        if weights.ndim == 2:
            # One set of weights for every goal: shared work, one (N, D) matrix.
            self.shared_weights = True
            if goal_count is None:
                goal_count = 1 if np.ndim(starts) == 1 else np.shape(starts)[0]
            self._weights = read_only(weights)
        elif weights.ndim == 3:
            self.shared_weights = False
            goal_count = weights.shape[0]
            self._weights = read_only(weights.transpose(1, 2, 0))  # (N, D, K)
        else:
            raise ValueError(f"weights must be (N, D) or (K, N, D), got shape {weights.shape}")
        if not np.isfinite(weights).all():
            raise ValueError("weights contain NaN or infinite values")
        dimension = weights.shape[-1] if dimension is None else dimension
        if weights.shape[-2:] != (settings.basis_count, dimension):
            raise ValueError(f"weights have shape {weights.shape}; the settings say "
                             f"{settings.basis_count} basis functions, of {dimension} numbers")
        self.goal_count = goal_count_of(goal_count)
        self.dimension = dimension
        scaling = np.ones((goal_count, dimension), bool) if amplitude_scaling is None else (
            np.broadcast_to(np.asarray(amplitude_scaling, bool), (goal_count, dimension)))
        self.amplitude_scaling = read_only(scaling.T)  # (D, K)
        centres, widths = settings.basis()
        self._centres, self._widths = read_only(centres), read_only(widths)

    @classmethod
    def from_dmps(cls, dmps):
        """A bank of the given single DMPs (same duration and settings)."""
        if not dmps:
            raise ValueError("a DMP bank needs at least one DMP")
        first = dmps[0]
        if any(d.duration != first.duration or d.settings != first.settings for d in dmps):
            raise ValueError("all DMPs of a bank must share duration and settings")
        return cls(np.stack([d.weights for d in dmps]), np.stack([d.start for d in dmps]),
                   first.duration, first.settings,
                   np.stack([d.amplitude_scaling for d in dmps]))

    @classmethod
    def straight(cls, start, goal_count, duration, settings=DmpSettings()):
        """K straight DMPs from `start` to goals given at run time (no demonstration); for
        orientations, along the shorter arc (slerp). Ijspeert: the minimum-jerk shape, shared
        by all goals and scaled by each one's amplitude (`g - y0`, or `-e0`); Pastor: `f = 0`,
        whose attractor already slides from the start to the goal."""
        dimension = cls._straight_dimension(start)
        goal_count_of(goal_count)
        if dmp_settings(settings).formulation == "ijspeert":
            weights = straight_weights(settings, duration, np.ones(dimension))
        else:
            weights = np.zeros((settings.basis_count, dimension))
        return cls(weights, start, duration, settings, goal_count=goal_count)

    @property
    def settings(self):
        """The bank's gains and basis (a copy: changing it does not change the bank)."""
        return dataclasses.replace(self._settings)

    def decay(self, dt):
        """The phase factor `exp(-alpha_x dt / tau)` of one step."""
        return phase_decay(self._settings, self.duration, dt)

    def subset(self, indices):
        """The bank of the DMPs `indices` (M,) alone, in that order: a new immutable bank
        with the same duration and settings and those DMPs' weights, starts and amplitude
        scaling (what drawing a few of K DMPs' paths steps, instead of all K)."""
        indices = goal_indices(indices, self.goal_count)
        starts = self.starts[:, indices].T
        scaling = self.amplitude_scaling[:, indices].T
        weights = (self._weights if self.shared_weights
                   else self._weights[:, :, indices].transpose(2, 0, 1))  # (M, N, D)
        return type(self)(weights, starts, self.duration, self._settings, scaling,
                          goal_count=indices.size)

    def predict(self, phase, start, velocity, goals, dt, steps, workspace=None):
        """Open-loop paths `(K, steps + 1, rows)` from one state (`start` `(rows, 1)` or
        `(rows, K)`), for drawing predictions; the inputs are left alone. `workspace`
        saves allocating one (the paths are new anyway)."""
        positive(dt, "dt")
        if not is_whole(steps):
            raise ValueError(f"steps must be a whole number >= 0, got {steps!r}")
        workspace = self.make_workspace() if workspace is None else workspace
        path = np.empty((int(steps) + 1,) + self.starts.shape)
        path[0] = np.broadcast_to(start, self.starts.shape)
        phase = np.array(phase, dtype=float)
        velocity = np.array(velocity, dtype=float)
        for step in range(int(steps)):
            self.advance_into(phase, path[step], velocity, goals, dt, phase, path[step + 1],
                              velocity, workspace)
        return path.transpose(2, 0, 1)


class DmpBankModel(BankStep, BankModel):
    """K DMPs, one per goal, stepped together from one shared robot state, arrays laid out
    `(D, K)`. All share `duration` and `settings`; each has its own weights (or all share
    one set), start and phase. `initial_state` and the pure `advance` give and step a state;
    `advance_into` is the same step into the caller's arrays, with a workspace from
    `make_workspace` (its parts: `pbp_drake.core.dmp.stepping`). docs/concepts/dmp.md,
    "The bank: K DMPs at once".
    """

    def __init__(self, weights, starts, duration, settings=DmpSettings(),
                 amplitude_scaling=None, goal_count=None):
        self._keep_model(weights, starts, duration, settings, amplitude_scaling, goal_count,
                         None)
        self.starts = read_only(
            broadcast_goalwise(starts, self.goal_count, self.dimension, "starts"))
        self._derive_constants()
        self._frozen = True

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

    @staticmethod
    def _straight_dimension(start):
        return as_point(start, "start").size

    def make_workspace(self):
        """New scratch arrays for the in-place step; one per thread or Drake Context."""
        return DmpWorkspace(self.dimension, self.goal_count, self._settings.basis_count)

    def initial_state(self, position=None):
        """(phase (K,), position (D, K), scaled velocity (D, K)) at the start of a movement."""
        positions = np.array(self.starts) if position is None else np.repeat(
            as_point(position, "position", dimension=self.dimension)[:, None],
            self.goal_count, axis=1)
        return (np.ones(self.goal_count), positions,
                np.zeros((self.dimension, self.goal_count)))

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
        check_positions(goals.reshape(self.goal_count, self.dimension), "goal")
        return goals.reshape(self.goal_count, self.dimension).T

    def advance(self, phase, positions, scaled_velocity, goals_dk, dt, locked=None,
                robot_velocity=None, followed=None):
        """One first-order-hold step of all K DMPs; pure: returns the new state
        `(phase, positions, scaled_velocity)`, new arrays.

        `phase` (K,); `positions` (D, K) or (D, 1) to step from (PBP passes the robot's);
        `scaled_velocity` (D, K) the DMPs' own `z`; `goals_dk` (D, K). `locked`: None, a bool
        or (K,) bools freezing those DMPs' phases; their velocity then follows
        `robot_velocity` (D,) and their position stays. `followed`: None (each DMP keeps its
        own velocity), or the index of the DMP the robot followed until now: every DMP then
        steps from that DMP's velocity, so that the robot may switch to any of them without
        a jump of its commanded velocity (PBP's goal switch, docs/concepts/hand-over.md).
        """
        phase = np.asarray(phase, dtype=float)
        scaled_velocity = followed_velocity(np.asarray(scaled_velocity, dtype=float), followed,
                                            self.goal_count)
        new_phase = np.empty(phase.shape)
        new_positions = np.empty(scaled_velocity.shape)
        new_velocity = np.empty(scaled_velocity.shape)
        self.advance_into(phase, positions, scaled_velocity, goals_dk, dt,
                          new_phase, new_positions, new_velocity, self.make_workspace(),
                          locked, robot_velocity)
        return new_phase, new_positions, new_velocity

    def advance_into(self, phase, positions, scaled_velocity, goals_dk, dt,
                     out_phase, out_positions, out_velocity, workspace, locked=None,
                     robot_velocity=None):
        """`advance` written into `out_phase` (K,), `out_positions` and `out_velocity` (D, K),
        with `workspace` (from `make_workspace`) as scratch.

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
                    out_velocity, workspace, np.broadcast_to(locked, np.shape(phase)),
                    robot_velocity)
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
        dp, dz = workspace.dp, workspace.dz
        self.attractor_terms_into(phase, positions, goals_dk, dt, dp, dz, workspace)
        # Positions first: `out_velocity` may alias `scaled_velocity`, which they read.
        self.stepped_positions_into(positions, dp, scaled_velocity, dt, out_positions,
                                    workspace)
        self.stepped_velocity_into(dz, scaled_velocity, dt, out_velocity)
        np.multiply(phase, self.decay(dt), out=out_phase)

    def _advance_partly_locked(self, phase, positions, scaled_velocity, goals_dk, dt,
                               out_phase, out_positions, out_velocity, workspace, locked,
                               robot_velocity):
        """Some DMPs locked, some not: the plain path with temporaries (rare)."""
        phase = np.array(phase, dtype=float)
        positions = np.array(np.broadcast_to(positions, np.shape(scaled_velocity)), float)
        scaled_velocity = np.array(scaled_velocity, dtype=float)
        new_phase = np.empty_like(phase)
        new_positions = np.empty_like(scaled_velocity)
        new_velocity = np.empty_like(scaled_velocity)
        self.advance_into(phase, positions, scaled_velocity, goals_dk, dt,
                          new_phase, new_positions, new_velocity, workspace)
        held = (scaled_velocity if robot_velocity is None
                else self.duration * np.asarray(robot_velocity, float)[:, None])
        out_phase[...] = np.where(locked, phase, new_phase)
        out_positions[...] = np.where(locked, positions, new_positions)
        out_velocity[...] = np.where(locked, held, new_velocity)
