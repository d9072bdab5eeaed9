"""The HSR station's whole-body differential IK: a velocity plan within the joints'
position, velocity and acceleration limits, and the desired state the plant's PD tracks."""

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.systems.framework import LeafSystem

# How much more a unit of hand-velocity error (m/s, rad/s) weighs than a unit of the arm's
# drift toward its ready pose (rad/s), when the limits do not allow both.
TASK_WEIGHT = 1e6
# The weight of falling short along the desired twist (rather than straying from it).
ALONG_WEIGHT = 1e5


def solve_box_qp(H, g, lower, upper, max_iterations=100):
    """``argmin 0.5 x'Hx - g'x`` subject to ``lower <= x <= upper`` (H positive definite,
    ``lower <= upper``), by a primal active-set method: exact, and quick for the few
    variables of a robot's joints."""
    x = np.linalg.solve(H, g)
    if np.all(x >= lower) and np.all(x <= upper):
        return x
    x = np.clip(x, lower, upper)
    fixed = (x <= lower) | (x >= upper)
    tolerance = 1e-12 * (1.0 + np.abs(g).max())
    for _ in range(max_iterations):
        free = ~fixed
        target = x.copy()
        if free.any():
            H_free = H[free]
            target[free] = np.linalg.solve(H_free[:, free], g[free] - H_free[:, fixed] @ x[fixed])
        step = target - x
        with np.errstate(divide="ignore", invalid="ignore"):
            reach = np.where(step < 0, (lower - x) / step,
                             np.where(step > 0, (upper - x) / step, np.inf))
        reach[fixed] = np.inf
        blocking = int(np.argmin(reach))
        if reach[blocking] < 1.0:
            # Go as far as the first bound in the way and hold that variable there.
            x = np.clip(x + reach[blocking] * step, lower, upper)
            x[blocking] = lower[blocking] if step[blocking] < 0 else upper[blocking]
            fixed[blocking] = True
            continue
        x = np.clip(target, lower, upper)
        gradient = H @ x - g
        # A held variable may leave its bound if the cost falls that way.
        leaving = fixed & (lower < upper) & (((x <= lower) & (gradient < -tolerance))
                                             | ((x >= upper) & (gradient > tolerance)))
        if not leaving.any():
            return x
        fixed[int(np.argmax(np.abs(gradient) * leaving))] = False
    return x


class WholeBodyDiffIk(LeafSystem):
    """Plans the robot's joint motion toward a desired end-effector pose, one step of
    differential IK at a time, and tells the plant's PD where to be.

    .. pydrake_system::

        name: WholeBodyDiffIk
        input_ports:
        - X_WE_desired
        - robot_state
        output_ports:
        - desired_state

    At each step ``t_n`` (period ``time_step``) it picks the velocity ``v_n`` that
    brings the end effector from the plan's pose to ``X_WE_desired`` by ``t_n +
    time_step`` as nearly as the joints' position, velocity and acceleration limits
    allow (a least-squares QP; the accelerations relative to the plan's previous
    velocity; where the limits bind, the hand rather falls short along its motion than
    strays from it), and in the rest of the joint space drifts toward ``q_nominal`` at
    ``centering_gain`` (1/s, per joint). The plan then moves at ``v_n`` until ``t_n +
    time_step``: it is piecewise linear in position. ``X_WE_desired`` is thus read as
    the pose to have at the end of the step.

    Drake's ``DifferentialInverseKinematicsIntegrator`` does not do for this: it keeps
    positions only, so it would take acceleration limits relative to zero velocity (a
    limit ``a`` caps every speed at ``a time_step``), and its QP scales the whole hand
    motion down to meet a limit, which made the hand surge and stall under acceleration
    limits.

    ``desired_state`` is ``[q_d, v_d]`` of the motor joints (``motor_joints``, in that
    order): the plan's position ``plant_time_step`` ahead of now and its velocity. The
    plant's implicit PD compares q_d with its positions at the end of its step, so the
    plan's position at that time is what it must be given to track without lag.
    ``robot_state`` (the plant's state) is read only at initialization: the plan
    starts there, at rest.

    Limits are pairs (lower, upper) of arrays over the plant's velocities (positions for
    ``position_limits``); ``inf`` where there is none. The plant must have q̇ = v.
    """

    def __init__(self, plant, frame_E, time_step, plant_time_step, motor_joints, *,
                 position_limits, velocity_limits, acceleration_limits, q_nominal,
                 centering_gain):
        super().__init__()
        nq, nv = plant.num_positions(), plant.num_velocities()
        if nq != nv:
            raise ValueError("WholeBodyDiffIk needs q̇ = v (no quaternion joints)")
        self._plant = plant
        self._frame_E = frame_E
        self._time_step = float(time_step)
        self._look_ahead = float(plant_time_step)
        self._plant_context = plant.CreateDefaultContext()
        self._nq = nq
        self._position_indices = np.array([joint.position_start() for joint in motor_joints])
        self._velocity_indices = np.array([joint.velocity_start() for joint in motor_joints])
        self._q_lower, self._q_upper = (np.asarray(bound, float) for bound in position_limits)
        self._v_lower, self._v_upper = (np.asarray(bound, float) for bound in velocity_limits)
        self._a_lower, self._a_upper = (np.asarray(bound, float)
                                        for bound in acceleration_limits)
        self._q_nominal = np.asarray(q_nominal, float)
        self._centering_gain = np.broadcast_to(np.asarray(centering_gain, float), (nq,))
        self._identity = np.eye(nv)
        self._identity6 = np.eye(6)
        self._pose_port = self.DeclareAbstractInputPort(
            "X_WE_desired", AbstractValue.Make(RigidTransform()))
        self._robot_state_port = self.DeclareVectorInputPort(
            "robot_state", plant.num_multibody_states())
        # [q at t_end, v, t_end]: the plan reaches q at t_end moving at v.
        self._plan = self.DeclareDiscreteState(nq + nv + 1)
        self.DeclarePeriodicDiscreteUpdateEvent(self._time_step, 0.0, self._step)
        self.DeclareInitializationDiscreteUpdateEvent(self._start)
        self._desired_port = self.DeclareVectorOutputPort(
            "desired_state", 2 * len(motor_joints), self._calc_desired_state,
            {self.time_ticket(), self.xd_ticket()})

    def get_X_WE_desired_input_port(self):
        return self._pose_port

    def get_robot_state_input_port(self):
        return self._robot_state_port

    def get_desired_state_output_port(self):
        return self._desired_port

    def _start(self, context, discrete_state):
        q = self._robot_state_port.Eval(context)[:self._nq]
        discrete_state.set_value(np.concatenate([q, np.zeros(self._nq),
                                                 [context.get_time()]]))

    def _step(self, context, discrete_state):
        plan = context.get_discrete_state(self._plan).get_value()
        q, v = plan[:self._nq], plan[self._nq:2 * self._nq]
        dt = self._time_step
        v_next = self._solve(q, v, self._pose_port.Eval(context))
        q_next = np.clip(q + dt * v_next, self._q_lower, self._q_upper)
        discrete_state.set_value(np.concatenate([q_next, v_next, [context.get_time() + dt]]))

    def _solve(self, q, v, X_WE_desired):
        """The velocity for the next step: the hand's desired twist in least squares,
        the drift to the nominal positions in the Jacobian's null space, in the limits."""
        plant, context, dt = self._plant, self._plant_context, self._time_step
        plant.SetPositions(context, q)
        world = plant.world_frame()
        X_WE = self._frame_E.CalcPose(context, world)
        J = plant.CalcJacobianSpatialVelocity(context, JacobianWrtVariable.kV, self._frame_E,
                                              np.zeros(3), world, world)
        rotation = (X_WE_desired.rotation() @ X_WE.rotation().inverse()).ToAngleAxis()
        twist = np.concatenate([rotation.axis() * rotation.angle(),
                                X_WE_desired.translation() - X_WE.translation()]) / dt
        # The projector onto J's null space, I - J⁺J (damped a little, should J lose
        # rank at a singularity of the arm).
        null_space = self._identity - J.T @ np.linalg.solve(J @ J.T + 1e-10 * self._identity6,
                                                            J)
        centering = self._centering_gain * (self._q_nominal - q)
        # Where the limits do not allow the whole twist, falling short along it costs
        # less than straying from it: the hand slows down rather than swerve.
        norm = np.linalg.norm(twist)
        W = TASK_WEIGHT * self._identity6
        if norm > 0:
            along = twist / norm
            W = W - (TASK_WEIGHT - ALONG_WEIGHT) * np.outer(along, along)
        JW = J.T @ W
        H = JW @ J + null_space
        g = JW @ twist + null_space @ centering
        # Within the velocity limits, the acceleration limits from v, and the position
        # limits by the end of the step; where the last two conflict, brake.
        accel_lower = v + self._a_lower * dt
        accel_upper = v + self._a_upper * dt
        lower = np.maximum(np.maximum(self._v_lower, accel_lower), (self._q_lower - q) / dt)
        upper = np.minimum(np.minimum(self._v_upper, accel_upper), (self._q_upper - q) / dt)
        conflict = lower > upper
        lower[conflict] = upper[conflict] = np.clip(0.0, accel_lower, accel_upper)[conflict]
        return solve_box_qp(H, g, lower, upper)

    def _calc_desired_state(self, context, output):
        plan = context.get_discrete_state(self._plan).get_value()
        q, v, t_end = plan[:self._nq], plan[self._nq:2 * self._nq], plan[-1]
        q_d = q + v * (context.get_time() + self._look_ahead - t_end)
        output.SetFromVector(np.concatenate(
            [q_d[self._position_indices], v[self._velocity_indices]]))
