"""How the virtual participant sees obstacles around the robot, in pure NumPy: the robot's
footprint (the HSR's, or a fixed-base arm's), where moving obstacles will stop, where the
DMP will take the hand, and when its own way round has stalled, so that it pushes on
through as people in the paper's study did (docs/tasks/obstacles.md, "The virtual
participant among obstacles")."""

import numpy as np

# How far the HSR's hand stands in front of its base in the task's start pose (m).
HAND_AHEAD_OF_BASE = 0.53
# The footprint kept clear of obstacles: the base (and the body over it) as a disc, the arm
# as a thick segment from the base to the hand (m).
BASE_RADIUS = 0.25
ARM_RADIUS = 0.08
# A fixed-base arm's footprint: a thick segment from its base to the hand (m), its links
# and the pedestal under them seen from above.
FIXED_ARM_RADIUS = 0.06
# How far ahead on its line the DMP aims when it pulls the hand back (m).
POLICY_LOOKAHEAD = 0.25


def footprint_clearance(hands, headings, obstacles, radius, fixed_base=None):
    """The smallest gap (m) between the robot's footprint and cylinders of `radius`.

    `hands` (..., 2) and `headings` (...) place the footprint: a disc of `BASE_RADIUS` at
    `HAND_AHEAD_OF_BASE` behind the hand and the arm, a segment of `ARM_RADIUS` from there
    to the hand. With a `fixed_base` (2,), an arm's, the footprint is the segment of
    `FIXED_ARM_RADIUS` from it to the hand, whatever the heading. `obstacles` (..., N, 2)
    broadcast against them. Returns (...)."""
    hands = np.asarray(hands, float)
    if fixed_base is not None:
        return _segment_clearance(np.broadcast_to(np.asarray(fixed_base, float), hands.shape),
                                  hands, obstacles, FIXED_ARM_RADIUS) - radius
    headings = np.broadcast_to(headings, hands.shape[:-1])
    arm = HAND_AHEAD_OF_BASE * np.stack([np.cos(headings), np.sin(headings)], axis=-1)
    bases = hands - arm
    relative = np.asarray(obstacles, float) - bases[..., None, :]
    base_gap = np.linalg.norm(relative, axis=-1) - BASE_RADIUS
    along = np.clip((relative * arm[..., None, :]).sum(-1) / HAND_AHEAD_OF_BASE ** 2, 0.0, 1.0)
    arm_gap = np.linalg.norm(relative - along[..., None] * arm[..., None, :], axis=-1) - ARM_RADIUS
    return np.minimum(base_gap, arm_gap).min(axis=-1) - radius


def _segment_clearance(starts, ends, obstacles, thickness):
    """The smallest gap (m) between the segments `starts` to `ends` (..., 2) of
    `thickness` and the points `obstacles` (..., N, 2)."""
    segment = ends - starts
    relative = np.asarray(obstacles, float) - starts[..., None, :]
    length2 = np.maximum((segment ** 2).sum(-1), 1e-12)
    along = np.clip((relative * segment[..., None, :]).sum(-1) / length2[..., None], 0.0, 1.0)
    gaps = np.linalg.norm(relative - along[..., None] * segment[..., None, :], axis=-1)
    return gaps.min(axis=-1) - thickness


def predict_obstacles(obstacles, velocities, hand, target_xy, times):
    """Where the obstacles will be at `times` (T,): moving on until they reach the line
    from the hand to the target, where they stop. Returns (T, N, 2)."""
    line = target_xy - hand
    length = np.linalg.norm(line)
    normal = (np.array([-line[1], line[0]]) / length if length > 1e-9 else np.zeros(2))
    side = (obstacles - hand) @ normal
    closing = velocities @ normal
    with np.errstate(divide="ignore", invalid="ignore"):
        stop = np.where((side * closing < 0.0) & (np.abs(closing) > 1e-6),
                        -side / closing, np.inf)
    travel = np.minimum(np.asarray(times, float)[:, None], stop[None, :])
    return obstacles[None] + travel[..., None] * velocities[None]


def policy_path(hand, start, target_xy, speed, times):
    """Roughly where the DMP takes the hand when let go: toward a point a little ahead on
    its straight path from the start to the target (it pulls back to that line)."""
    path = target_xy - start
    length = np.linalg.norm(path)
    unit = path / length if length > 1e-9 else np.zeros(2)
    points, point, now = [], np.array(hand, float), 0.0
    for time in times:
        along = np.clip((point - start) @ unit + POLICY_LOOKAHEAD, 0.0, length)
        aim = start + along * unit - point
        gap = np.linalg.norm(aim)
        step = min(gap, speed * (time - now))
        point = point + (aim / gap * step if gap > 1e-9 else 0.0)
        points.append(point)
        now = time
    return np.array(points)


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
