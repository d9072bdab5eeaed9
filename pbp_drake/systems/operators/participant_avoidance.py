"""How the virtual participant notices that its way round the obstacles has stalled.

Its local plan (`VirtualOperator._plan`) scores motions over a horizon of a second or
two. When the cylinders settle into a wall across the line to the target, every motion
that keeps clear gets no closer, and standing still would win each tick, forever. People
in the paper's study pushed on through at such moments, at the risk of a collision; the
participant does the same once it has not come `progress_step` closer to the target for
`stall_time` (`VirtualParticipantParams`), and keeps pushing until it arrives (turning back
to avoiding would park it at the next wall, a few centimetres on).
"""

import numpy as np

# The watch's state: [closest distance to the target so far (m), seconds since it got
# closer, 1 once it has given up on going round]. The layout of the participant's discrete
# state, not a behaviour: no scenario field.
WATCH_SIZE = 3


def start_watch(distance):
    """The watch's state when the participant first sees the task."""
    return np.array([float(distance), 0.0, 0.0])


def update_watch(params, watch, distance, elapsed):
    """The watch after one tick of `elapsed` seconds that left the hand `distance` (m)
    from the target: a new array `[closest, stalled_for, pushing]`. It counts as getting
    closer once it beats its best distance by `params.progress_step`, and gives up going
    round after `params.stall_time` without (`VirtualParticipantParams`)."""
    closest, stalled_for, pushing = (float(value) for value in watch)
    if distance < closest - params.progress_step:
        closest, stalled_for = distance, 0.0
    else:
        stalled_for += elapsed
    if stalled_for >= params.stall_time:
        pushing = 1.0
    return np.array([closest, stalled_for, pushing])


def is_pushing_through(watch):
    """Whether the participant has given up going round and heads straight for the target."""
    return bool(watch[2] > 0.5)


def robot_closes_in(params, velocity, offset, nominal_speed):
    """Whether the hand's `velocity` (2) carries it toward the target, `offset` (2) away,
    at `params.min_closing_fraction` of `nominal_speed` or more: in the last few centimetres
    (PBP) the participant leaves the robot alone only then.

    In PBP-Alt every takeover freezes the DMP's phase, so after a run of takeovers the DMP
    is still early in its motion when the hand is almost there; early on, its forcing term
    holds it back against the spring (a demonstration starts slowly), and a few
    centimetres from the target the two balance: the hand parks there. A person would
    drive the last bit.
    """
    distance = np.linalg.norm(offset)
    if distance < 1e-9:
        return True
    return float(np.asarray(velocity) @ np.asarray(offset)) / distance >= (
        params.min_closing_fraction * nominal_speed)
