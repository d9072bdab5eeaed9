"""Six-DoF blending: the operator's twist and the policy's pose reference become one pose
reference (`PoseReference`), and the six-DoF hand-over law. The laws are the position ones
(`pbp_drake.core.arbitration`) with the orientation on SO(3): over one period `dt` the
operator's twist `u = (u_v, u_w)` alone takes the hand to `U = (y + u_v dt, Exp(u_w dt) q)`;
angular velocities add and mix as vectors, orientations are turned by `Exp` or mixed by
`quaternion.slerp`; ``pbp_no_user`` is the policy alone. The table and why:
docs/concepts/six-dof.md, "The blending laws"."""

from typing import NamedTuple

import numpy as np

from pbp_drake.core import quaternion
from pbp_drake.core.arbitration import (
    BLEND_LAWS, OPERATOR, POLICY, SHIFTED, BlendLaw, played_reference)
from pbp_drake.core.hand_over import check_limit, limited_velocity

TWIST_FIELDS = ("vx", "vy", "vz", "wx", "wy", "wz")


class PoseReference(NamedTuple):
    """A pose to be at after one control period and the twist to move at (world frame)."""

    position: np.ndarray  # (3,) m
    orientation: np.ndarray  # (4,) unit quaternion (w, x, y, z)
    velocity: np.ndarray  # (3,) m/s
    angular_velocity: np.ndarray  # (3,) rad/s

    @classmethod
    def from_vector(cls, vector):
        """From `[x, y, z, qw, qx, qy, qz, vx, vy, vz, wx, wy, wz]` (`PoseState`'s layout)."""
        vector = np.asarray(vector, dtype=float).reshape(13)
        return cls(vector[:3].copy(), vector[3:7].copy(), vector[7:10].copy(),
                   vector[10:13].copy())

    def to_vector(self):
        """`[x, y, z, qw, qx, qy, qz, vx, vy, vz, wx, wy, wz]`, a new array."""
        return np.concatenate([self.position, self.orientation, self.velocity,
                               self.angular_velocity])


class HandOverLimits(NamedTuple):
    """The six-DoF hand-over's limits: the linear ones of `pbp_drake.core.hand_over` and
    their angular twins (rad/s^2 and rad/s). The commanded angular velocity then changes by
    at most `max_angular_acceleration * dt` between two ticks."""

    max_acceleration: float
    max_speed: float
    max_angular_acceleration: float
    max_angular_speed: float

    def checked(self):
        """The limits as floats; raises ValueError naming the first that is not finite and
        positive."""
        units = ("m/s^2", "m/s", "rad/s^2", "rad/s")
        return HandOverLimits(*(check_limit(value, name, unit) for value, name, unit in
                                zip(self, self._fields, units)))


def validate_twist(twist, name="operator_twist"):
    """The twist `(vx, vy, vz, wx, wy, wz)` as a new float array; raises ValueError naming
    `name` and the fields that are NaN or infinite, or the wrong size."""
    twist = np.array(twist, dtype=float).reshape(-1)
    if twist.size != len(TWIST_FIELDS):
        raise ValueError(f"{name} must be 6 numbers {TWIST_FIELDS}, got {twist.size}")
    bad = np.flatnonzero(~np.isfinite(twist))
    if bad.size:
        fields = ", ".join(TWIST_FIELDS[i] for i in bad)
        raise ValueError(f"{name} {fields} is NaN or infinite: {twist.tolist()}")
    return twist


def turned(orientation, angular_velocity, dt):
    """`Exp(w dt) q`: the orientation `q` (4,) turned for `dt` at the world-frame angular
    velocity `w` (3,), signed as `q` (a stream of them stays continuous)."""
    turn = quaternion.exp_map(np.asarray(angular_velocity, dtype=float) * dt)
    return quaternion.aligned(quaternion.multiply(turn, orientation), orientation)


def blend_pose(mode, robot_position, robot_orientation, policy, twist, active, dt,
               alpha=None):
    """The pose reference of one control period under `mode` (module docstring).

    `policy` is the policy's `PoseReference` (the selected DMP's next pose and twist);
    `twist` the operator's `(vx, vy, vz, wx, wy, wz)`, refused when NaN or infinite;
    `active` whether the operator acts; `alpha` the weight of ``fixed_alpha`` and
    ``confidence_alpha``. The orientations must be unit quaternions (within
    `quaternion.UNIT_TOLERANCE`), else ValueError. The result is signed as the robot's
    orientation."""
    twist = validate_twist(twist)
    linear, angular = twist[:3], twist[3:]
    robot_orientation = np.asarray(robot_orientation, dtype=float)
    policy = PoseReference(*(np.asarray(part, dtype=float) for part in policy))
    for name, orientation in (("robot_orientation", robot_orientation),
                              ("policy orientation", policy.orientation)):
        # Checked, not divided by its norm: a quaternion of norm 2 would turn out of norm 2.
        quaternion.unit_norm(orientation, name)
    policy = policy._replace(orientation=quaternion.aligned(policy.orientation,
                                                            robot_orientation))
    reference = played_reference(mode, active, alpha, POSE_BLEND_LAWS)
    if reference == POLICY:
        return policy
    if reference == SHIFTED:
        return PoseReference(policy.position + linear * dt,
                             turned(policy.orientation, angular, dt),
                             policy.velocity + linear, policy.angular_velocity + angular)
    operator = PoseReference(np.asarray(robot_position, dtype=float) + linear * dt,
                             turned(robot_orientation, angular, dt), linear, angular)
    if reference == OPERATOR:
        return operator
    return PoseReference(
        (1.0 - alpha) * operator.position + alpha * policy.position,
        quaternion.slerp(operator.orientation, policy.orientation, alpha),
        (1.0 - alpha) * operator.velocity + alpha * policy.velocity,
        (1.0 - alpha) * operator.angular_velocity + alpha * policy.angular_velocity)


#: The six-DoF laws by mode: the position ones (`BLEND_LAWS`) and ``pbp_no_user``, the
#: policy alone.
POSE_BLEND_LAWS = {**BLEND_LAWS, "pbp_no_user": BlendLaw(POLICY, POLICY)}
POSE_BLEND_MODES = tuple(POSE_BLEND_LAWS)


def pose_hand_over(previous_velocity, previous_angular_velocity, reference, limits, dt):
    """The command `PoseReference` of one tick under the six-DoF hand-over law.

    Linear part: `pbp_drake.core.hand_over.hand_over`; angular part, the same velocity law
    with the angular limits, and the orientation turned by the angular velocity not yet
    reached, `q'_k = Exp((w'_k - w_k) dt) q_k`, as the position is shifted. `limits` is a
    checked `HandOverLimits`; the previous velocities are the command's of the tick before.
    New arrays."""
    velocity = limited_velocity(previous_velocity, reference.velocity,
                                limits.max_acceleration * dt, limits.max_speed)
    angular = limited_velocity(previous_angular_velocity, reference.angular_velocity,
                               limits.max_angular_acceleration * dt,
                               limits.max_angular_speed)
    return PoseReference(
        np.asarray(reference.position, dtype=float) + (velocity - reference.velocity) * dt,
        turned(reference.orientation, angular - reference.angular_velocity, dt),
        velocity, angular)
