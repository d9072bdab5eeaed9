"""The frame a person steers the hand in with a six-DoF browser operator, and the twist its
keys or sticks give (NumPy; `systems.twist_operator` reads them).

The operator frame follows the hand's heading on the floor, as the person sees the robot:
`forward` is horizontal, `left = up x forward`, and `up` is world +z. Translations go along
these three axes. Rotations are the hand's yaw about world +z (as the 4-DoF operators' Q/E),
its pitch about `left` (positive tips the approach axis down) and its roll about its own
approach axis z_H (the grasp task's roll rho): a side grasp differs by a yaw, a top grasp is
a pitch down then a roll (docs/tasks/grasp.md)."""

import numpy as np

from pbp_drake.core.participant_grasp import without_forward

UP = np.array([0.0, 0.0, 1.0])


def hand_axes(orientation):
    """The world directions of x_H, y_H, z_H (columns of a 3x3) for a unit quaternion
    `(w, x, y, z)` (4,)."""
    w, x, y, z = orientation
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def operator_frame(orientation):
    """`(forward, left, up)` world unit vectors (3,) of the operator frame of a hand at
    `orientation`. The heading is the floor direction of z_H, blended towards that of x_H
    by the square of z_H's vertical component, with x_H signed to lean the way the hand was
    pitched (+x_H pointing down, -x_H up: the HSR's start hand, x_H up, pitched down turns
    x_H ahead). For a side grasp it is the approach's floor angle (the station's
    `heading`); it stays continuous through a pitch straight down or up."""
    axes = hand_axes(orientation)
    approach = axes[:, 2]
    blend = approach - approach[2] * abs(approach[2]) * axes[:, 0]
    heading = np.array([blend[0], blend[1], 0.0])
    norm = np.linalg.norm(heading)
    # A pose whose two horizontal parts cancel exactly would have no heading: take world +x
    # rather than none.
    forward = heading / norm if norm > 1e-9 else np.array([1.0, 0.0, 0.0])
    return forward, np.cross(UP, forward), UP.copy()


def operator_twist(orientation, linear, angular):
    """The world twist `[v (3), w (3)]` of `linear` `(forward, left, up)` m/s and `angular`
    `(yaw, pitch, roll)` rad/s in the operator frame of a hand at `orientation`."""
    forward, left, up = operator_frame(orientation)
    approach = hand_axes(orientation)[:, 2]
    velocity = linear[0] * forward + linear[1] * left + linear[2] * up
    rate = angular[0] * up + angular[1] * left + angular[2] * approach
    return np.concatenate([velocity, rate])


def without_forward_twist(twist, orientation):
    """`twist` with the forward part of its velocity along the approach axis z_H removed (the
    paper's disabled forward key; `participant_grasp.without_forward`), rotation kept."""
    twist = np.array(twist, float)
    twist[:3] = without_forward(twist[:3], orientation)
    return twist


def capped(vector):
    """`vector` scaled down to length 1 if it is longer: two controls pushed together go no
    faster than one pushed fully."""
    norm = np.linalg.norm(vector)
    return vector / norm if norm > 1.0 else np.asarray(vector, float)
