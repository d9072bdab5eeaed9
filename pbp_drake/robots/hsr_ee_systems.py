"""The HSR station's two task-space adapters: the end-effector command in, its state out."""

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.math import SpatialVelocity
from pydrake.systems.framework import LeafSystem

from pbp_drake.systems.layouts import EeCommand, EeState


def heading_of(R_WE: RotationMatrix) -> float:
    """The direction the hand points in the floor plane: atan2 of its z axis' (x, y)."""
    z_axis = R_WE.matrix()[:, 2]
    return float(np.arctan2(z_axis[1], z_axis[0]))


class EeCommandToPose(LeafSystem):
    """Turns the end-effector command into the desired pose for diff IK.

    .. pydrake_system::

        name: EeCommandToPose
        input_ports:
        - ee_command
        output_ports:
        - X_WE_desired

    `ee_command` is `[p (3), v (3), heading]` (`EeCommand`); the pose is
    `(Rz(heading) R_E0, position)` where `R_E0` is the hand pointing along world +x, and
    the position is where the command puts the hand `lead` seconds after now.

    With a `command_period` (a control loop that sends, at each tick, the state to be in at
    the next tick), the position ramps into `p` at velocity `v`: `p - v (t_next - t -
    lead)`. Tracking `p` as a step once a tick would leave the robot behind by most of a
    tick's travel, and a policy re-integrated from the robot's state (PBP) would then run
    slow. Without one, the position is `p + v lead`.

    `lead` is how far ahead the reader wants the pose: the station's diff IK reads it as
    the pose to have at the end of its step, so it is the diff IK's period there.
    """

    def __init__(self, R_E0: RotationMatrix, command_period=None, lead=0.0):
        super().__init__()
        self._R_E0 = RotationMatrix(R_E0)
        self._period = command_period
        self._lead = float(lead)
        self._command_port = self.DeclareVectorInputPort("ee_command", EeCommand.size)
        self._pose_port = self.DeclareAbstractOutputPort(
            "X_WE_desired", lambda: AbstractValue.Make(RigidTransform()), self._calc_pose)

    def get_ee_command_input_port(self):
        return self._command_port

    def get_pose_output_port(self):
        return self._pose_port

    def _calc_pose(self, context, output):
        command = EeCommand(self._command_port.Eval(context))
        R = RotationMatrix.MakeZRotation(command.heading) @ self._R_E0
        position = np.array([command.x, command.y, command.z])
        velocity = np.array([command.vx, command.vy, command.vz])
        ahead = self._lead
        if self._period:
            time = context.get_time()
            next_tick = np.ceil(time / self._period - 1e-9) * self._period
            ahead -= max(0.0, next_tick - time)
        position = position + velocity * ahead
        output.set_value(RigidTransform(R, position))


class EeStateFromPlant(LeafSystem):
    """Reads the end effector's position, velocity and heading off the plant's outputs.

    .. pydrake_system::

        name: EeStateFromPlant
        input_ports:
        - body_poses
        - body_spatial_velocities
        output_ports:
        - ee_state

    `ee_state` is `[p_WE (3), v_WE (3), heading, heading_rate]` (`EeState`); heading_rate
    is the hand's angular velocity about world z (the rate of the heading while the hand's
    z axis stays near the floor plane).
    """

    def __init__(self, ee_body_index):
        super().__init__()
        self._index = int(ee_body_index)
        self._poses_port = self.DeclareAbstractInputPort(
            "body_poses", AbstractValue.Make([RigidTransform()]))
        self._velocities_port = self.DeclareAbstractInputPort(
            "body_spatial_velocities", AbstractValue.Make([SpatialVelocity()]))
        self._state_port = self.DeclareVectorOutputPort(
            "ee_state", EeState.size, self._calc_state)

    def get_body_poses_input_port(self):
        return self._poses_port

    def get_body_spatial_velocities_input_port(self):
        return self._velocities_port

    def get_ee_state_output_port(self):
        return self._state_port

    def _calc_state(self, context, output):
        X_WE = self._poses_port.Eval(context)[self._index]
        V_WE = self._velocities_port.Eval(context)[self._index]
        w, v = V_WE.rotational(), V_WE.translational()
        output.SetFromVector(np.concatenate(
            [X_WE.translation(), v, [heading_of(X_WE.rotation()), w[2]]]))
