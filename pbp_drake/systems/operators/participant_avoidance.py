"""How the virtual participant notices that its way round the obstacles has stalled.

When the cylinders settle into a wall across the line to the target, no motion that keeps
clear gets closer; as people in the paper's study did, the participant then pushes on
through until it arrives (docs/tasks/obstacles.md, "The virtual participant among obstacles").
"""

import numpy as np

# The watch's state: [closest distance to the target so far (m), seconds since it got
# closer, 1 once it has given up on going round].
WATCH_SIZE = 3


def start_watch(distance):
    """The watch's state when the participant first sees the task."""
    return np.array([float(distance), 0.0, 0.0])


def update_watch(params, watch, distance, elapsed):
    """The watch after one tick of `elapsed` seconds that left the hand `distance` (m)
    from the target: closer once it beats its best by `params.progress_step`, giving up
    going round after `params.stall_time` without."""
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
    the participant leaves the robot alone only then (docs/tasks/obstacles.md).
    """
    distance = np.linalg.norm(offset)
    if distance < 1e-9:
        return True
    return float(np.asarray(velocity) @ np.asarray(offset)) / distance >= (
        params.min_closing_fraction * nominal_speed)
