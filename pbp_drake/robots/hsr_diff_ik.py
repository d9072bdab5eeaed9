"""The HSR station's whole-body differential IK: a velocity plan within the joints'
velocity and acceleration limits, and the desired state the plant's PD tracks."""

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.multibody.inverse_kinematics import (
    DifferentialInverseKinematicsStatus,
    DoDifferentialInverseKinematics,
)
from pydrake.systems.framework import LeafSystem


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

    At each step ``t_n`` (period ``time_step``) it solves Drake's differential IK QP
    (``DoDifferentialInverseKinematics`` with ``parameters``) for the velocity ``v_n``
    that brings the end effector from the plan's pose to ``X_WE_desired`` by ``t_n +
    time_step``, within the joints' position, velocity and acceleration limits; the
    acceleration limits are taken relative to the plan's previous velocity
    ``v_{n-1}``. (Drake's ``DifferentialInverseKinematicsIntegrator`` keeps positions
    only, so it would take them relative to zero: an acceleration limit ``a`` would cap
    every speed at ``a time_step``.) The plan then moves at ``v_n`` until ``t_n +
    time_step``: it is piecewise linear in position.

    ``X_WE_desired`` is thus read as the pose to have at the end of the step. When the
    QP has no solution (position and acceleration limits that cannot both hold), the
    plan brakes every joint at its acceleration limit. Positions stay within their
    limits (clamped), velocities within theirs.

    ``desired_state`` is ``[q_d, v_d]`` of the motor joints (``motor_joints``, in that
    order): the plan's position ``plant_time_step`` ahead of now and its velocity. The
    plant's implicit PD compares q_d with its positions at the end of its step, so the
    plan's position at that time is what it must be given to track without lag.
    ``robot_state`` (the plant's state) is read only at initialization: the plan
    starts there, at rest.
    """

    def __init__(self, plant, frame_E, time_step, parameters, plant_time_step,
                 motor_joints):
        super().__init__()
        self._plant = plant
        self._frame_E = frame_E
        self._time_step = float(time_step)
        self._parameters = parameters
        self._parameters.set_time_step(self._time_step)
        self._look_ahead = float(plant_time_step)
        self._plant_context = plant.CreateDefaultContext()
        nq, nv = plant.num_positions(), plant.num_velocities()
        if nq != nv:
            raise ValueError("WholeBodyDiffIk needs q̇ = v (no quaternion joints)")
        self._nq = nq
        self._position_indices = np.array([joint.position_start() for joint in motor_joints])
        self._velocity_indices = np.array([joint.velocity_start() for joint in motor_joints])
        unbounded = (np.full(nq, -np.inf), np.full(nq, np.inf))
        self._q_lower, self._q_upper = parameters.get_joint_position_limits() or unbounded
        self._v_lower, self._v_upper = parameters.get_joint_velocity_limits() or unbounded
        self._a_lower, self._a_upper = (parameters.get_joint_acceleration_limits()
                                        or unbounded)
        self._pose_port = self.DeclareAbstractInputPort(
            "X_WE_desired", AbstractValue.Make(RigidTransform()))
        self._robot_state_port = self.DeclareVectorInputPort(
            "robot_state", plant.num_multibody_states())
        # [q at t_end, v, t_end]: the plan reaches q at t_end moving at v.
        self._plan = self.DeclareDiscreteState(nq + nv + 1)
        self.DeclarePeriodicDiscreteUpdateEvent(self._time_step, 0.0, self._step)
        self.DeclareInitializationDiscreteUpdateEvent(self._start)
        motors = len(motor_joints)
        self._desired_port = self.DeclareVectorOutputPort(
            "desired_state", 2 * motors, self._calc_desired_state,
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
        self._plant.SetPositions(self._plant_context, q)
        self._plant.SetVelocities(self._plant_context, v)
        result = DoDifferentialInverseKinematics(
            self._plant, self._plant_context, self._pose_port.Eval(context), self._frame_E,
            self._parameters)
        # Within the limits as the QP states them; OSQP's tolerance lets its solution
        # stray past a bound by up to about 1e-3. With no solution, brake.
        v_lower = np.maximum(self._v_lower, v + self._a_lower * self._time_step)
        v_upper = np.minimum(self._v_upper, v + self._a_upper * self._time_step)
        if result.status == DifferentialInverseKinematicsStatus.kNoSolutionFound:
            v_next = np.clip(np.zeros_like(v), v_lower, v_upper)
        else:
            v_next = np.clip(result.joint_velocities, v_lower, v_upper)
        q_next = np.clip(q + self._time_step * v_next, self._q_lower, self._q_upper)
        discrete_state.set_value(np.concatenate(
            [q_next, v_next, [context.get_time() + self._time_step]]))

    def _calc_desired_state(self, context, output):
        plan = context.get_discrete_state(self._plan).get_value()
        q, v, t_end = plan[:self._nq], plan[self._nq:2 * self._nq], plan[-1]
        q_d = q + v * (context.get_time() + self._look_ahead - t_end)
        output.SetFromVector(np.concatenate(
            [q_d[self._position_indices], v[self._velocity_indices]]))
