"""The HSR pose station's task-space adapters: a six-DoF hand command (`PoseState`) in, as
the arithmetic the station's diff IK applies itself (`PoseCommandRamp`), and the hand's
measured pose and twist out (`PoseStateFromPlant`). The hand frame H (`HAND_FRAME`) and the
conventions (quaternions mapping H to the world, world-frame angular velocities):
docs/tasks/grasp.md, "Frames and conventions"."""

import numpy as np
from pydrake.common.eigen_geometry import Quaternion
from pydrake.math import RotationMatrix

from pbp_drake.core.quaternion import UNIT_TOLERANCE, aligned, exp_map, multiply
from pbp_drake.robots.hsr_ee_systems import CommandRamp, FrameStateFromPlant
from pbp_drake.systems.ports import PoseState, finite_pose_state

# The frame the pose station commands and measures: the grasp task's hand frame H.
HAND_FRAME = "hand_palm_link"
# PoseState's entries, by index.
_POSITION, _QUATERNION, _VELOCITY, _ANGULAR = (slice(0, 3), slice(3, 7), slice(7, 10),
                                               slice(10, 13))


def check_pose_command(command, name="pose_command"):
    """The command's unit quaternion (4,), or ValueError naming the fields that are NaN or
    infinite, or the quaternion whose norm is not within `UNIT_TOLERANCE` of 1 (rather
    than NaN joint targets that the plant's PD would follow into a crash)."""
    command = finite_pose_state(command, name)
    quaternion = command[_QUATERNION]
    norm = float(np.sqrt(quaternion @ quaternion))
    if abs(norm - 1.0) > UNIT_TOLERANCE:
        raise ValueError(f"{name} (qw, qx, qy, qz) {quaternion.tolist()} is not a unit "
                         f"quaternion: norm {norm:.9g}, must be within {UNIT_TOLERANCE:g} "
                         f"of 1")
    return quaternion / norm


class PoseCommandRamp(CommandRamp):
    """What `WholeBodyDiffIk` aims at, read from a six-DoF command `pose_command`
    (`PoseState`: the hand's pose to be at, `[p (3), q (4)]`, and the twist to move at,
    `[v (3), w (3)]`, world frame).

    `X_WE_desired` at time t is the command carried along its own twist for
    `CommandRamp.ahead` seconds, `(Exp(w ahead) q, p + v ahead)` (a ramp between ticks, as
    `EeCommandToPose`'s); `V_WE_desired` is `[w, v]`.
    """

    port_name = "pose_command"
    command_size = PoseState.size

    def declare_heading_sample(self, system, command_port):
        """No state: the command's twist is its own rate."""
        return None

    def desired(self, context, last_heading_index, command, time):
        """As `EeCommandRamp.desired`; refuses a NaN or non-unit command
        (`check_pose_command`)."""
        quaternion = check_pose_command(command, self.port_name)
        ahead = self.ahead(time)
        turned = multiply(exp_map(command[_ANGULAR] * ahead), quaternion)
        position = command[_POSITION] + command[_VELOCITY] * ahead
        velocity = np.concatenate([command[_ANGULAR], command[_VELOCITY]])
        return RotationMatrix(Quaternion(turned)), position.tolist(), velocity.tolist()


class PoseStateFromPlant(FrameStateFromPlant):
    """Reads the hand's pose and twist off the plant's state.

    .. pydrake_system::

        name: PoseStateFromPlant
        input_ports:
        - plant_state
        output_ports:
        - hand_pose

    `plant_state` is `plant`'s state output; `hand_pose` is `[p_WH (3), q_WH (4), v_WH (3),
    w_WH (3)]` (`PoseState`) of `frame_H`, world frame. Of `q` and `-q` it gives the one
    nearer `q_reference` (the station passes the hand's start orientation), so that the
    stream does not flip sign as Drake's conversion from a rotation matrix may.
    """

    def __init__(self, plant, frame_H, q_reference):
        super().__init__(plant, frame_H, "hand_pose", PoseState.size)
        self._reference = np.asarray(q_reference, float)

    def _calc_output(self, context, output):
        X_WH, V_WH = self._kinematics(context)
        quaternion = aligned(X_WH.rotation().ToQuaternion().wxyz(), self._reference)
        output.SetFromVector(np.concatenate([X_WH.translation(), quaternion,
                                             V_WH.translational(), V_WH.rotational()]))
