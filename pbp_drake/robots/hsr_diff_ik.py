"""The HSR station's whole-body differential IK: a velocity plan within the joints'
position, velocity and acceleration limits, and the desired state the plant's PD tracks.
Its QP is `pbp_drake.robots.box_qp`'s."""

import numpy as np
from numpy._core.umath import clip as _clip
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.systems.framework import LeafSystem

from pbp_drake.robots.box_qp import solve_box_qp
from pbp_drake.systems.ports import PortGetters

# How much more a unit of the hand's velocity error (m/s) weighs than a unit of the joints'
# drift toward their nominal positions (m/s, rad/s): the drift takes what the hand's motion
# leaves free and costs the hand nothing measurable.
TASK_WEIGHT = 1e6
# Where the limits do not allow the whole desired twist, falling short along it weighs a
# tenth of straying from it: the hand slows down rather than swerve.
ALONG_WEIGHT = 0.1
# An angular velocity error of 1 rad/s weighs as 0.32 m/s: where the limits bind, the
# hand's heading gives before its position.
ROTATION_WEIGHT = 0.1
# With `limit_overshoot` (the pose station), a step whose hand would move along the twist
# further than the twist itself is solved again with its part along the twist weighing this
# many times the rest, and then, if the palm still moves further along the linear twist
# than it (turning less to move more), with that too: the hand does not run ahead of the
# command where the limits bind.
OVERSHOOT_WEIGHT = 10.0
# With a `limit_margin`, the speed (rad/s or m/s) per unit of a joint's depth inside the
# margin at which the plan's free joint motion pushes it back out. Chosen on the Panda's
# tuning seeds (PBP-Alt and PBP-Cont, 100 trials each, margins 0.2 to 0.5 rad, gains 10 to
# 100/s): 3 of the 200 trials stalled without the push (2 with `brake_at_limits`), 1 with
# 0.3 rad and 25 or 50/s (50 the faster); at 10/s it freed fewer, and a 0.5 rad margin
# stalled others.
LIMIT_PUSH_GAIN = 50.0
# The plan closes its gap to the command over this many steps (the command's own velocity
# is fed forward), so that what the limits held back is not made up in one burst.
CATCH_UP_STEPS = 3


class WholeBodyDiffIk(PortGetters, LeafSystem):
    """Plans the robot's joint motion toward a desired end-effector pose, one step of
    differential IK at a time, and tells the plant's PD where to be.

    .. pydrake_system::

        name: WholeBodyDiffIk
        input_ports:
        - ee_command (with an EeCommandRamp; pose_command with a PoseCommandRamp)
        - robot_state
        output_ports:
        - desired_state

    ``command_ramp`` (``EeCommandRamp``, ``PoseCommandRamp``) names and sizes the command
    port and makes from the command the hand's desired pose ``X_WE_desired`` and twist
    ``V_WE_desired`` (world frame, ``[w, v]``). Each step (period ``time_step``) picks the
    plan's velocity until the next: ``V_WE_desired`` plus what closes the gap from the
    plan's pose to ``X_WE_desired`` (the pose to have at the end of the step) over
    ``CATCH_UP_STEPS`` steps, as nearly as the joints' position, velocity and acceleration
    limits allow (a least-squares QP, the accelerations relative to the plan's previous
    velocity), the rest of the joint space drifting toward ``q_nominal`` at
    ``centering_gain`` (1/s, per joint). The plan is piecewise linear in position. Not
    Drake's ``DifferentialInverseKinematicsIntegrator`` (docs/tasks/hsr-station.md).

    ``desired_state`` is ``[q_d, v_d]`` of ``motor_joints`` (in that order): the plan's
    position ``look_ahead`` seconds ahead and its velocity (the plant's implicit PD
    compares q_d with its positions at the end of its step; 0 for kinematic joints).
    ``robot_state`` is read only at initialization: the plan starts there, at rest (before
    that, at ``q_nominal``).

    Limits are (lower, upper) pairs of arrays over the plant's velocities (positions for
    ``position_limits``), ``inf`` for none; the plant must have q̇ = v. See
    ``OVERSHOOT_WEIGHT`` for ``limit_overshoot``; ``singular_margin`` and ``limit_margin``
    are ``ArmStationConfig``'s (see ``LIMIT_PUSH_GAIN``). With ``brake_at_limits`` (the
    arms') a joint's speed toward a position limit is at most ``sqrt(2 a d)`` at ``d`` from
    it, ``a`` its acceleration limit: it stops at the limit rather than in one step there.
    """

    def __init__(self, plant, frame_E, time_step, look_ahead, motor_joints, *,
                 position_limits, velocity_limits, acceleration_limits, q_nominal,
                 centering_gain, command_ramp, limit_overshoot=False, singular_margin=0.0,
                 limit_margin=0.0, brake_at_limits=False):
        super().__init__()
        self._limit_overshoot = bool(limit_overshoot)
        self._singular_margin = float(singular_margin)
        self._limit_margin = float(limit_margin)
        nq, nv = plant.num_positions(), plant.num_velocities()
        if nq != nv:
            raise ValueError("WholeBodyDiffIk needs q̇ = v (no quaternion joints)")
        self._plant = plant
        self._frame_E = frame_E
        self._time_step = float(time_step)
        self._look_ahead = float(look_ahead)
        self._plant_context = plant.CreateDefaultContext()
        self._nq = nq
        self._position_indices = np.array([joint.position_start() for joint in motor_joints])
        self._velocity_indices = np.array([joint.velocity_start() for joint in motor_joints])
        self._q_lower, self._q_upper = (np.asarray(bound, float) for bound in position_limits)
        self._v_lower, self._v_upper = (np.asarray(bound, float) for bound in velocity_limits)
        self._a_lower, self._a_upper = (np.asarray(bound, float)
                                        for bound in acceleration_limits)
        self._q_nominal = np.asarray(q_nominal, float)
        self._catch_up_time = CATCH_UP_STEPS * self._time_step
        # The acceleration and position limits' pairs as rows, both bounds in one call.
        self._a_step_bounds = np.stack([self._a_lower * self._time_step,
                                        self._a_upper * self._time_step])
        self._q_bounds = np.stack([self._q_lower, self._q_upper])
        # With `brake_at_limits`: which position bounds brake (those with a finite
        # acceleration limit toward them), 2 a dt for each, and which are upper bounds.
        two_a_dt = 2.0 * self._time_step * np.stack([-self._a_lower, self._a_upper])
        self._braked = (np.isfinite(two_a_dt) & np.isfinite(self._q_bounds)
                        & bool(brake_at_limits))
        self._two_a_dt = two_a_dt[self._braked]
        self._braked_upper = np.nonzero(self._braked)[0] == 1
        self._centering_gain = np.broadcast_to(np.asarray(centering_gain, float), (nq,))
        self._identity = np.eye(nv)
        self._task_weights = TASK_WEIGHT * np.array([ROTATION_WEIGHT] * 3 + [1.0] * 3)
        # The Jacobian's rows scaled as the task weighs them, relative to the translation's.
        self._singular_rows = np.sqrt(self._task_weights / TASK_WEIGHT)[:, None]
        self._world = plant.world_frame()
        self._origin = np.zeros(3)
        self._motor_count = len(motor_joints)
        # Where desired_state's [q_end, v] of the motors and the plan's end time sit in it.
        self._desired_gather = np.concatenate([self._position_indices,
                                               nq + self._velocity_indices])
        self._t_end = nq + nv
        self._ramp = command_ramp
        self._command_port = self.DeclareVectorInputPort(command_ramp.port_name,
                                                         command_ramp.command_size)
        self._robot_state_port = self.DeclareVectorInputPort(
            "robot_state", plant.num_multibody_states())
        # [q at t_end, v, t_end, hold]: the plan reaches q at t_end moving at v; hold is
        # which velocities the last step's QP held at a bound (its next first guess).
        self._plan = self.DeclareDiscreteState(np.concatenate(
            [self._q_nominal, np.zeros(nv + 1 + nv)]))  # at q_nominal until initialized
        self.DeclarePeriodicDiscreteUpdateEvent(self._time_step, 0.0, self._step)
        self.DeclareInitializationDiscreteUpdateEvent(self._start)
        self._last_heading = command_ramp.declare_heading_sample(self, self._command_port)
        self._desired_port = self.DeclareVectorOutputPort(
            "desired_state", 2 * len(motor_joints), self._calc_desired_state,
            {self.time_ticket(), self.xd_ticket()})

    def get_command_input_port(self):
        """The command port, whichever command the ramp reads."""
        return self._command_port

    def _start(self, context, discrete_state):
        q = self._robot_state_port.Eval(context)[:self._nq]
        discrete_state.set_value(self._plan, np.concatenate(
            [q, np.zeros(self._nq), [context.get_time()], np.zeros(self._nq)]))

    def _step(self, context, discrete_state):
        plan = context.get_discrete_state(self._plan).get_value()
        n, dt = self._nq, self._time_step
        q, v, hold = plan[:n], plan[n:2 * n], plan[2 * n + 1:]
        time = context.get_time()
        v_next, hold = self._solve(q, v, *self._ramp.desired(
            context, self._last_heading, self._command_port.Eval(context), time), hold)
        # In place, by np.clip's own ufunc: its Python wrapper costs more than the clip.
        new_plan = discrete_state.get_mutable_value(self._plan)
        _clip(q + dt * v_next, self._q_lower, self._q_upper, out=new_plan[:n])
        new_plan[n:2 * n] = v_next
        new_plan[2 * n] = time + dt
        new_plan[2 * n + 1:] = hold

    def _singular_damping(self, J):
        """Damped least squares near a singular configuration: with s the Jacobian's least
        singular value (its rows in the task weights, over the translation's), a weight
        TASK_WEIGHT (margin² - s²) on the joint velocities while s < margin, so that no
        joint pair spins to move the hand along a direction it has all but lost."""
        smallest = np.linalg.svd(J * self._singular_rows, compute_uv=False)[-1]
        margin = self._singular_margin
        return TASK_WEIGHT * (margin * margin - smallest * smallest) if smallest < margin else 0.0

    def _solve(self, q, v, R_WE_desired, p_WE_desired, V_WE_desired, hold):
        """The velocity for the next step, and which velocities it holds at a bound (both
        bounds as the rows of (2, n) arrays: one numpy call per pair)."""
        plant, context, dt, world = self._plant, self._plant_context, self._time_step, self._world
        plant.SetPositions(context, q)
        X_WE = self._frame_E.CalcPose(context, world)
        J = plant.CalcJacobianSpatialVelocity(context, JacobianWrtVariable.kV, self._frame_E,
                                              self._origin, world, world)
        rotation = (R_WE_desired @ X_WE.rotation().inverse()).ToAngleAxis()
        # The gap [axis angle, p_desired - p] and the twist V + (gap - dt V) / catch-up,
        # entry by entry in Python floats: numpy's elementwise operations in the same
        # order, without seven numpy calls on 3- and 6-vectors at each step.
        angle, catch_up_time = rotation.angle(), self._catch_up_time
        gap = [entry * angle for entry in rotation.axis().tolist()]
        gap += [desired - now for desired, now in zip(p_WE_desired,
                                                      X_WE.translation().tolist())]
        twist = np.array([V + (error - dt * V) / catch_up_time
                          for V, error in zip(V_WE_desired, gap)])
        # The cost |J v - twist|² in the task weights D, with its part along the twist
        # weighing ALONG_WEIGHT of the rest: W = D - (1 - ALONG_WEIGHT) D t t' D / t'D t.
        JD = J.T * self._task_weights
        JDt = JD @ twist
        H0 = JD @ J + self._identity
        if self._singular_margin > 0.0:
            H0 = H0 + self._singular_damping(J) * self._identity
        g0 = self._centering_gain * (self._q_nominal - q)
        if self._limit_margin > 0.0:
            # Each joint's depth inside the margin of its lower and its upper limit (0
            # outside, and for a joint without a limit), pushed back at LIMIT_PUSH_GAIN.
            margin = self._limit_margin
            inside_lower = np.maximum(margin - (q - self._q_lower), 0.0)
            inside_upper = np.maximum(margin - (self._q_upper - q), 0.0)
            g0 = g0 + LIMIT_PUSH_GAIN * (inside_lower - inside_upper)
        H, g = H0, g0
        norm = twist @ (self._task_weights * twist)
        if norm > 0:
            # np.outer's product, scaled in place: (1 - ALONG_WEIGHT) / norm * outer.
            outer = np.multiply.outer(JDt, JDt)
            outer *= (1.0 - ALONG_WEIGHT) / norm
            H = np.subtract(H0, outer, out=outer)
            g = g0 + ALONG_WEIGHT * JDt
        # Within the velocity limits, the acceleration limits from v, and the position
        # limits by the end of the step; where the last two conflict, brake.
        accel = v + self._a_step_bounds
        reach = self._q_bounds - q
        reach /= dt
        if self._two_a_dt.size:
            # With `brake_at_limits`, at most the speed toward a position limit from which
            # the joint stops within its acceleration limit: sqrt(2 a d) at d from it (a
            # joint that met its limit at speed stopped in one step, and the hand jumped).
            toward = reach[self._braked]
            stopping = np.sqrt(self._two_a_dt * np.abs(toward))
            reach[self._braked] = np.where(self._braked_upper, np.minimum(toward, stopping),
                                           np.maximum(toward, -stopping))
        lower = np.maximum(np.maximum(self._v_lower, accel[0]), reach[0])
        upper = np.minimum(np.minimum(self._v_upper, accel[1]), reach[1])
        conflict = lower > upper
        if conflict.any():
            lower[conflict] = upper[conflict] = np.clip(0.0, accel[0], accel[1])[conflict]
        v_next, hold_next = solve_box_qp(H, g, lower, upper, hold)
        if not self._limit_overshoot:
            return v_next, hold_next
        if norm > 0 and JDt @ v_next > norm:
            # Ahead of the twist along it: weigh that part OVERSHOOT_WEIGHT times the rest.
            H = H0 - (1.0 - OVERSHOOT_WEIGHT) / norm * (JDt[:, None] * JDt)
            g = g0 + OVERSHOOT_WEIGHT * JDt
            v_next, hold_next = solve_box_qp(H, g, lower, upper, hold_next)
        linear = twist[3:]
        speed2 = linear @ linear
        Jl = J[3:].T @ linear
        if speed2 > 0 and Jl @ v_next > speed2:
            # The palm ahead of the linear twist (turning less to move more, rotation being
            # cheap): add OVERSHOOT_WEIGHT (l'J v - |l|^2)^2 / |l|^2 in the task weight.
            weighted = Jl * (TASK_WEIGHT * OVERSHOOT_WEIGHT / speed2)
            H = H + weighted[:, None] * Jl
            g = g + weighted * speed2
            v_next, hold_next = solve_box_qp(H, g, lower, upper, hold_next)
        return v_next, hold_next

    def _calc_desired_state(self, context, output):
        # Evaluated at every plant step: [q_end, v] of the motors gathered in one call,
        # q_end += ahead v in place, set as the output in one call.
        plan = context.get_discrete_state(self._plan).get_value()
        desired = plan[self._desired_gather]
        ahead = context.get_time() + self._look_ahead - plan[self._t_end]
        q_d = desired[:self._motor_count]
        q_d += ahead * desired[self._motor_count:]
        output.SetFromVector(desired)
