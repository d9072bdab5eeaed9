"""The HSR station's two task-space adapters: the end-effector command in, its state out."""

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.systems.framework import LeafSystem

from pbp_drake.systems.layouts import EeCommand, EeState
from pbp_drake.systems.tick import decide_offset

# EeCommand's entries, by index.
_POSITION, _VELOCITY, _HEADING = slice(0, 3), slice(3, 6), 6


def heading_of(R_WE: RotationMatrix) -> float:
    """The direction the hand points in the floor plane: atan2 of its z axis' (x, y)."""
    z_axis = R_WE.matrix()[:, 2]
    return float(np.arctan2(z_axis[1], z_axis[0]))


class EeCommandToPose(LeafSystem):
    """Turns the end-effector command into the desired pose and velocity for diff IK.

    .. pydrake_system::

        name: EeCommandToPose
        input_ports:
        - ee_command
        output_ports:
        - X_WE_desired
        - V_WE_desired

    `ee_command` is `[p (3), v (3), heading]` (`EeCommand`). `X_WE_desired` is where the
    command puts the hand `lead` seconds from now, `(Rz(heading) R_E0, position)` with
    `R_E0` the hand pointing along world +x; `V_WE_desired` is the hand's spatial velocity
    `[w (3), v (3)]` in the world frame along the way.

    With a `command_period` (a control loop that sends, at each tick, the state to be in at
    the next tick) both ramp: the position into `p` at `v`, `p - v (t_next - t - lead)`,
    and the heading into the command's from the last tick's command, at a constant rate.
    Stepping to `p` and the heading once a tick would leave the robot behind by most of a
    tick's travel (a policy re-integrated from the robot's state, PBP, would then run
    slow), and would ask the robot for the whole turn at once. The last tick's heading is
    sampled just after each tick, before a controller that decides at the PBP loop's
    decide stage (`pbp_drake.systems.tick`) changes the command. Without a
    `command_period`, the position is `p + v lead` and the heading the command's.

    `lead` is how far ahead the reader wants the pose: the station's diff IK reads it as
    the pose to have at the end of its step, so it is the diff IK's period there.
    """

    def __init__(self, R_E0: RotationMatrix, command_period=None, lead=0.0):
        super().__init__()
        self._R_E0 = RotationMatrix(R_E0)
        self._period = command_period
        self._lead = float(lead)
        self._command_port = self.DeclareVectorInputPort("ee_command", EeCommand.size)
        self._last_heading = self.DeclareDiscreteState(1)
        self.DeclareInitializationDiscreteUpdateEvent(self._sample_heading)
        if command_period:
            self.DeclarePeriodicDiscreteUpdateEvent(
                command_period, 0.5 * decide_offset(command_period), self._sample_heading)
        self._pose_port = self.DeclareAbstractOutputPort(
            "X_WE_desired", lambda: AbstractValue.Make(RigidTransform()), self._calc_pose)
        self._velocity_port = self.DeclareVectorOutputPort(
            "V_WE_desired", 6, self._calc_velocity)

    def get_ee_command_input_port(self):
        return self._command_port

    def get_pose_output_port(self):
        return self._pose_port

    def get_velocity_output_port(self):
        return self._velocity_port

    def _sample_heading(self, context, discrete_state):
        discrete_state.set_value(self._last_heading,
                                 [EeCommand(self._command_port.Eval(context)).heading])

    # The diff IK reads both outputs every step (100 Hz): they index the command vector
    # (EeCommand's layout) rather than build a named view of it each time.
    def _heading_rate(self, context, heading):
        if not self._period:
            return 0.0
        last = context.get_discrete_state(self._last_heading).get_value()[0]
        turn = (heading - last + np.pi) % (2 * np.pi) - np.pi
        return turn / self._period

    def _calc_velocity(self, context, output):
        command = self._command_port.Eval(context)
        velocity = output.get_mutable_value()
        velocity[:2] = 0.0
        velocity[2] = self._heading_rate(context, command[_HEADING])
        velocity[3:] = command[_VELOCITY]

    def _calc_pose(self, context, output):
        command = self._command_port.Eval(context)
        ahead = self._lead
        if self._period:
            time = context.get_time()
            next_tick = np.ceil(time / self._period - 1e-9) * self._period
            ahead -= max(0.0, next_tick - time)
        heading = command[_HEADING] + self._heading_rate(context, command[_HEADING]) * ahead
        R = RotationMatrix.MakeZRotation(heading) @ self._R_E0
        output.set_value(RigidTransform(R, command[_POSITION] + command[_VELOCITY] * ahead))


class EeStateFromPlant(LeafSystem):
    """Reads the end effector's position, velocity and heading off the plant's state.

    .. pydrake_system::

        name: EeStateFromPlant
        input_ports:
        - plant_state
        output_ports:
        - ee_state

    `plant_state` is `plant`'s state output; `ee_state` is `[p_WE (3), v_WE (3), heading,
    heading_rate]` (`EeState`) of `ee_body`; heading_rate is the hand's angular velocity
    about world z (the rate of the heading while the hand's z axis stays near the floor
    plane).

    The hand's kinematics come from a context of `plant` of this system's own, set to the
    plant's state: the same computation as the plant's `body_poses` and
    `body_spatial_velocities` outputs, whose values would cross into Python as a list of
    every body's pose and velocity (about half this system's time) for one body's.
    """

    def __init__(self, plant, ee_body):
        super().__init__()
        self._plant = plant
        self._body = ee_body
        self._plant_context = plant.CreateDefaultContext()
        self._plant_state_port = self.DeclareVectorInputPort(
            "plant_state", plant.num_multibody_states())
        self._state_port = self.DeclareVectorOutputPort(
            "ee_state", EeState.size, self._calc_state)

    def get_plant_state_input_port(self):
        return self._plant_state_port

    def get_ee_state_output_port(self):
        return self._state_port

    def _calc_state(self, context, output):
        plant_context = self._plant_context
        self._plant.SetPositionsAndVelocities(plant_context,
                                              self._plant_state_port.Eval(context))
        X_WE = self._body.EvalPoseInWorld(plant_context)
        V_WE = self._body.EvalSpatialVelocityInWorld(plant_context)
        w, v = V_WE.rotational(), V_WE.translational()
        output.SetFromVector(np.concatenate(
            [X_WE.translation(), v, [heading_of(X_WE.rotation()), w[2]]]))
