"""The DMP bank as a Drake system: K DMPs re-integrated each control step from the robot.

The system holds the bank's immutable model (`pbp_drake.core.dmp.DmpBank`) and nothing
else that a step changes: the DMPs' state is the Context's discrete state and the step's
scratch arrays (a `DmpWorkspace`) are a cache entry, which Drake allocates once per
Context. Two Contexts of one system, or two Simulators of one diagram, are therefore
independent, whichever order or thread steps them.
"""

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import LeafSystem, ValueProducer

from pbp_drake.core.dmp.stepping import limit_speeds
from pbp_drake.systems.layouts import goal_index
from pbp_drake.systems.tick import decide_offset


class DmpBank(LeafSystem):
    """Steps K DMPs (one per goal) every control period from the robot's measured state.

    .. pydrake_system::

        name: DmpBank
        input_ports:
        - robot_state
        - goals
        - operator_active (optional)
        - followed_goal (optional)
        output_ports:
        - references
        - phase
        - predicted_paths

    `robot_state` is `[position (D), velocity (D)]`; `goals` is K goals flattened row-major
    `(K, D)`. Each period the bank advances every DMP one step from the robot's position
    (keeping each DMP's own velocity; the first-order-hold step of `pbp_drake.core.dmp`). With
    `lock_phase_when_operator_acts` (PBP-Alt), a nonzero `operator_active` freezes the phases
    and the DMPs follow the robot until the operator lets go. With `max_speed` (m/s), each
    DMP's own velocity is scaled down to it before every step (anti-windup: PBP-Cont gives
    the hand-over law's speed limit, which the hand can never exceed anyway).

    `followed_goal` (optional) is the index of the goal whose reference the robot followed
    since the last update (the goal estimator's selection, read before it updates). When it
    is connected, each update first gives every DMP the followed DMP's velocity: all DMPs
    then step from the robot's position AND the velocity it is being driven at, so the
    selection may move to any of them without a jump of the commanded velocity (the
    velocities then differ by the attractors' pull over one period only, which vanishes with
    the period). Unconnected, each DMP keeps a velocity of its own, which relaxes toward its
    own attractor while the robot follows another.

    `references` is the K next states `[positions (K*D), velocities (K*D)]`, `phase` the K
    phases; `predicted_paths` (declared when `prediction_steps > 0`) is each DMP's open-loop
    path from its current state, `(K, prediction_steps + 1, D)` flattened, for drawing,
    sampled every `prediction_period` (default: the control period).
    All state lives in the Context, and so does the step's scratch memory (a cache entry).

    The state is one vector `[phase, held, p (D), z (D*K), dp (D*K), dz (D*K)]` (`_split` is
    the one place that knows the layout). PBP steps every DMP from the robot's position `p`
    and never from the DMP's own, and the step is affine in the DMP's velocity `z`
    (`p' = p + dp + Phi01 z`, `z' = dz + Phi11 z`, see `pbp_drake.core.dmp.stepping`), so
    the state keeps, of each step, what its outputs are read from: the DMPs' velocities `z`
    before the step and the step's attractor terms `dp`, `dz`; `references` reads the
    stepped positions and velocities out. With shared weights an update is then six passes
    over `(D, K)`, and Drake copies three `(D, K)` arrays; the goals are checked and laid
    out `(D, K)` in a cache entry, once per change. While `held` (at the start, and while
    PBP-Alt locks the phases) the DMPs sit at `p + dp` with velocity `z`. All DMPs of the
    system share one phase: the lock is one input.

    The bank updates at the decide stage of each control tick
    (`pbp_drake.systems.tick.decide_offset`), so that it reads the robot's state sampled at
    the tick and the operator's decision of the same tick, as Alg. 2 does. `update_offset`
    (seconds after the tick) overrides it, for experts with their own tick order.
    """

    def __init__(self, bank, control_period, lock_phase_when_operator_acts=False,
                 prediction_steps=0, update_offset=None, prediction_period=None,
                 max_speed=None):
        super().__init__()
        self._bank = bank
        # Anti-windup: the hand-over law never lets the hand move faster than this (m/s), so
        # a DMP must not remember a faster velocity either (see `_update`).
        self._max_speed = None if max_speed is None else float(max_speed)
        self._period = float(control_period)
        # Drawing a long horizon at the control period would cost hundreds of steps a frame;
        # the first-order-hold step stays close at coarser steps (second order in the step).
        self._prediction_period = float(prediction_period or control_period)
        self._lock = bool(lock_phase_when_operator_acts)
        self._prediction_steps = int(prediction_steps)
        if update_offset is None:
            update_offset = decide_offset(self._period)
        if not (np.isfinite(update_offset) and 0.0 <= update_offset < self._period):
            raise ValueError(
                f"update_offset must be in [0, control_period), got {update_offset!r}")
        k, d = bank.goal_count, bank.dimension
        self._robot_state_port = self.DeclareVectorInputPort("robot_state", 2 * d)
        self._goals_port = self.DeclareVectorInputPort("goals", k * d)
        self._operator_active_port = self.DeclareVectorInputPort("operator_active", 1)
        self._followed_goal_port = self.DeclareVectorInputPort("followed_goal", 1)
        # Held at the start: the DMPs sit at their starts (p = 0, dp = starts), at rest.
        initial = np.zeros(self.state_size(k, d))
        phase, held, _, _, dp, _ = self._split(initial)
        phase[0], held[0] = 1.0, 1.0
        dp[...] = bank.starts
        self._state_index = self.DeclareDiscreteState(initial)
        # The goals checked and laid out (D, K) once each time they change, not each tick.
        self._goals_dk = self.DeclareCacheEntry(
            "goals, validated, (D, K) contiguous",
            ValueProducer(allocate=lambda: AbstractValue.Make(np.zeros((d, k))),
                          calc=self._calc_goals_dk),
            prerequisites_of_calc={self._goals_port.ticket()})
        # Scratch of the bank's step, one workspace per Context. It is never calculated nor
        # marked up to date (it depends on nothing and holds nothing between calls), so
        # `_workspace` may always take it mutably; a cloned Context deep-copies it.
        self._workspace_entry = self.DeclareCacheEntry(
            "DmpWorkspace: scratch arrays of the bank's step",
            ValueProducer(allocate=lambda: AbstractValue.Make(bank.make_workspace()),
                          calc=self._never_calculated),
            prerequisites_of_calc={self.nothing_ticket()})
        # The outputs depend on the bank's own state only: say so, so that Drake does not
        # recompute them after every plant step.
        self._references_port = self.DeclareVectorOutputPort(
            "references", 2 * k * d, self._calc_references,
            prerequisites_of_calc={self.xd_ticket()})
        self._phase_port = self.DeclareVectorOutputPort(
            "phase", k, self._calc_phase, prerequisites_of_calc={self.xd_ticket()})
        self._predicted_paths_port = None
        if self._prediction_steps > 0:
            self._predicted_paths_port = self.DeclareVectorOutputPort(
                "predicted_paths", k * (self._prediction_steps + 1) * d,
                self._calc_predicted_paths,
                prerequisites_of_calc={self.xd_ticket(),
                                       self._goals_port.ticket()})
        self.DeclarePeriodicDiscreteUpdateEvent(self._period, update_offset, self._update)

    @staticmethod
    def state_size(goal_count, dimension):
        """The length of the one state vector `[phase, held, p, z, dp, dz]`."""
        return 2 + dimension + 3 * goal_count * dimension

    @property
    def bank(self):
        return self._bank

    def get_robot_state_input_port(self):
        return self._robot_state_port

    def get_goals_input_port(self):
        return self._goals_port

    def get_operator_active_input_port(self):
        return self._operator_active_port

    def get_followed_goal_input_port(self):
        return self._followed_goal_port

    def get_references_output_port(self):
        return self._references_port

    def get_phase_output_port(self):
        return self._phase_port

    def get_predicted_paths_output_port(self):
        return self._predicted_paths_port

    def _split(self, vector):
        """Views of a state vector: phase (1,), held (1,), p (D, 1), z, dp and dz (D, K)."""
        d, k = self._bank.dimension, self._bank.goal_count
        z, dp, dz = (2 + d + i * k * d for i in range(3))
        return (vector[0:1], vector[1:2], vector[2:2 + d].reshape(d, 1),
                vector[z:dp].reshape(d, k), vector[dp:dz].reshape(d, k),
                vector[dz:dz + k * d].reshape(d, k))

    def _workspace(self, context):
        """This Context's `DmpWorkspace` (see the cache entry's comment in `__init__`)."""
        return self._workspace_entry.get_mutable_cache_entry_value(
            context).GetMutableValueOrThrow()

    @staticmethod
    def _never_calculated(context, value):
        raise RuntimeError("the DmpBank workspace is scratch memory, never evaluated")

    def dmp_states(self, context):
        """The K DMPs' state after the last update: phases (K,), positions and scaled
        velocities (D, K), new arrays (what `references` reads out)."""
        bank = self._bank
        phase, held, robot, z, dp, dz = self._split(
            context.get_discrete_state(self._state_index).get_value())
        positions = np.empty(z.shape)
        velocity = np.empty(z.shape)
        if held[0]:
            np.add(robot, dp, out=positions)
            velocity[...] = z
        else:
            bank.stepped_positions_into(robot, dp, z, self._period, positions,
                                        self._workspace(context))
            bank.stepped_velocity_into(dz, z, self._period, velocity)
        return np.full(bank.goal_count, phase[0]), positions, velocity

    def _update(self, context, discrete_state):
        # Drake fills `discrete_state` with the current state; the update writes into it.
        bank, period = self._bank, self._period
        d = bank.dimension
        phase, held, robot, z, dp, dz = self._split(
            discrete_state.get_mutable_vector(self._state_index).get_mutable_value())
        # Every input is evaluated before the workspace is taken: an input's evaluation may
        # reach this system's outputs, whose calculation uses the same workspace.
        robot_state = self._robot_state_port.EvalAbstract(context).get_value().get_value()
        lock = (self._lock and self._operator_active_port.HasValue(context)
                and self._operator_active_port.Eval(context)[0] > 0.5)
        goals_dk = None if lock else self._goals_dk.Eval(context)
        # The goal the robot followed since the last update (None: unconnected).
        followed = goal_index(self._followed_goal_port, context, bank.goal_count)
        workspace = self._workspace(context)
        # The velocities the last step left, read out in place (see the class docstring).
        if not held[0]:
            bank.stepped_velocity_into(dz, z, period, z)
            if followed is not None:
                # Every DMP continues from the velocity of the one the robot followed, so
                # that a switch to another goal keeps the command's velocity.
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

    def _calc_goals_dk(self, context, value):
        goals = self._bank.goals_matrix(self._goals_port.Eval(context))
        value.get_mutable_value()[...] = goals

    def _calc_references(self, context, output):
        _, positions, scaled_velocity = self.dmp_states(context)
        d, k = self._bank.dimension, self._bank.goal_count
        references = output.get_mutable_value().reshape(2, k, d)
        references[0] = positions.T
        np.divide(scaled_velocity.T, self._bank.duration, out=references[1])

    def _calc_phase(self, context, output):
        phase = self._split(context.get_discrete_state(self._state_index).get_value())[0]
        output.get_mutable_value()[:] = phase[0]

    def _calc_predicted_paths(self, context, output):
        phase, positions, scaled_velocity = self.dmp_states(context)
        goals = self._goals_dk.Eval(context)
        paths = self._bank.predict(phase, positions, scaled_velocity, goals,
                                   self._prediction_period, self._prediction_steps,
                                   self._workspace(context))
        output.SetFromVector(paths.reshape(-1))
