"""The six-DoF hand-over law as a Drake system, between the pose blender and the hand."""

import numpy as np

from pbp_drake.core import quaternion
from pbp_drake.core.pose_arbitration import HandOverLimits, PoseReference, pose_hand_over
from pbp_drake.systems.pbp.hand_over import HandOverBase


class PoseHandOver(HandOverBase):
    """Passes the pose reference on with its linear and angular velocities each changing at
    most `max_acceleration * dt` and `max_angular_acceleration * dt` per tick and capped at
    the speeds (`pbp_drake.core.pose_arbitration.pose_hand_over`).

    .. pydrake_system::

        name: PoseHandOver
        input_ports:
        - reference
        output_ports:
        - command

    `reference` and `command` are `PoseState`s. The command is the state, held between
    ticks; it starts at `initial_pose` `[x, y, z, qw, qx, qy, qz]` at rest, and updates at
    the report stage of each tick, as `HandOver`.
    """

    def __init__(self, initial_pose, limits, control_period):
        initial_pose = np.asarray(initial_pose, dtype=float).reshape(-1)
        if initial_pose.size != 7 or not np.isfinite(initial_pose).all():
            raise ValueError(f"initial_pose must be 7 finite numbers [x, y, z, qw, qx, qy, qz], "
                             f"got {initial_pose.tolist()}")
        orientation = quaternion.unit_quaternions(initial_pose[3:], "initial_pose orientation")
        super().__init__(np.concatenate([initial_pose[:3], orientation, np.zeros(6)]),
                         control_period)
        try:
            self._limits = HandOverLimits(*limits).checked()
        except TypeError:
            raise ValueError(f"limits must be HandOverLimits (max_acceleration, max_speed, "
                             f"max_angular_acceleration, max_angular_speed), got "
                             f"{limits!r}") from None

    def _command(self, previous, reference):
        return pose_hand_over(previous[7:10], previous[10:13], PoseReference.from_vector(reference),
                              self._limits, self._period).to_vector()
