"""What the virtual participant does in the reaching task, in pure NumPy: with the forward
key it drives to the target (`drive_motion`); without it, it shows the target with what the
keys still allow (`assist_motion`: it turns to face it and moves along
`u_target - u_picked`, steps aside, or insists), first moving the hand to where the tool
can point at it (`reposition_motion`). With `vertical=True` the velocities are
`(vx, vy, vz)` instead of floor 2-vectors. The system
(`pbp_drake.systems.operators.virtual_operator`) adds the belief, the noise and the timing;
the behaviour in full: docs/tasks/reach.md, "The virtual participant"."""

import numpy as np

from pbp_drake.core.reach_task import heading_error, rotate_planar, wrap_angle


def unit(vector):
    """`vector` scaled to length 1 (zero stays zero)."""
    norm = np.linalg.norm(vector)
    return vector / norm if norm > 1e-9 else np.zeros_like(vector)


def facing(heading):
    """The floor unit vector the heading points along."""
    return np.array([np.cos(heading), np.sin(heading)])


def without_forward(velocity, heading):
    """The part of a floor `velocity` (2) the keys can command with the forward key
    disabled: its component along the heading removed when that component points forward."""
    ahead = facing(heading)
    return velocity - max(float(velocity @ ahead), 0.0) * ahead


def turn_rate(params, angle):
    """The yaw rate (rad/s) that turns the heading by `angle` (rad): full `rotation_speed`
    far from it, in proportion within `turn_slowdown_angle`, none once aligned."""
    if abs(angle) <= params.aligned_angle:
        return 0.0
    return float(np.sign(angle) * params.rotation_speed
                 * min(1.0, abs(angle) / params.turn_slowdown_angle))


def aside_direction(position, heading, target, picked):
    """+1 (left) or -1: the sidestep that widens the angle between the `target` and the
    `picked` object (positions, 3) when they stand almost in line.

    Stepping left by d turns the view of a point at distance r by -d / r, so the gap
    `angle(picked) - angle(target)` changes by `-d (1 / r_picked - 1 / r_target)`.
    """
    gap = heading_error(heading, position, picked) - heading_error(heading, position, target)
    closeness = (1.0 / max(np.linalg.norm(picked[:2] - position[:2]), 1e-6)
                 - 1.0 / max(np.linalg.norm(target[:2] - position[:2]), 1e-6))
    direction = -np.sign(gap) * np.sign(closeness)
    return direction if direction != 0 else 1.0


def faces_target(params, position, heading, target):
    """Whether the hand points at the target closely enough to count as facing it (twice
    `aligned_angle`: the turn stops within `aligned_angle`, and noise moves it)."""
    return abs(heading_error(heading, position, target)) <= 2 * params.aligned_angle


def assist_motion(params, speed, position, heading, target, picked, insisting,
                  vertical=False, heading_range=None):
    """The floor velocity (2, m/s) and yaw rate (rad/s) of a participant who sees the
    estimate name `picked` instead of `target` (positions, 3), the hand at `position` with
    `heading`; `insisting` once it has faced the target `insist_time` to no avail. No
    velocity it returns points forward (`without_forward`).

    `vertical`: the velocity is `(vx, vy, vz)` (3): vz = 0 and the floor part as without
    it, but when `insisting` (`insisting_motion`). `heading_range` (low, high), an arm's
    wrist (None: all the way round), bounds the heading an insisting participant turns to
    (`insisting_side_heading`)."""
    if insisting:
        return insisting_motion(params, speed, position, heading, target, heading_range,
                                vertical)
    if vertical:
        velocity, yaw_rate = assist_motion(params, speed, position, heading, target, picked,
                                           insisting)
        return np.array([velocity[0], velocity[1], 0.0]), yaw_rate
    toward_target = unit(target[:2] - position[:2])
    toward_picked = unit(picked[:2] - position[:2])
    separation = np.arccos(np.clip(toward_target @ toward_picked, -1.0, 1.0))
    if separation < params.in_line_angle:
        left = rotate_planar([0.0, 1.0], heading)
        side = aside_direction(position, heading, target, picked)
        velocity = params.aside_speed_fraction * speed * side * left
    else:
        velocity = speed * without_forward(unit(toward_target - toward_picked), heading)
    return velocity, turn_rate(params, heading_error(heading, position, target))


def _pointing_blocked(params, offset, heading_range, vertical):
    """`(beyond, over)`, the two reasons `can_point_at` is false for a target at `offset` (3)
    (straight above, its floor direction is no direction at all: the least motion swings
    it)."""
    over = vertical and np.linalg.norm(offset[:2]) < abs(offset[2])
    if heading_range is None:
        return False, over
    low, high = heading_range
    bearing = wrap_angle(np.arctan2(offset[1], offset[0]) - 0.5 * (low + high))
    return abs(float(bearing)) > 0.5 * (high - low) + params.aligned_angle, over


def can_point_at(params, position, target, heading_range=None, vertical=False):
    """Whether turning the tool, within `heading_range` (low, high) (None: all the way
    round), can point it at `target` (3) from `position` (3): the floor direction to the
    target lies within the range (give or take `aligned_angle`), and, with `vertical`
    motion, the target stands no more above or below the hand than beside it."""
    offset = np.asarray(target, float)[:3] - np.asarray(position, float)[:3]
    return not any(_pointing_blocked(params, offset, heading_range, vertical))


def reposition_motion(params, speed, position, heading, target, heading_range=None,
                      vertical=False):
    """The velocity (2, or 3 with `vertical`) and yaw rate that move the hand to where the
    tool can point at `target` (`can_point_at` false): with the target's floor direction
    beyond `heading_range`, back along the range's middle direction (never forward: the
    tool points within a quarter turn of it); with the target more above or below than
    beside, toward its height; both at once combined into `speed`. It turns the tool to
    the heading in the range nearest the target's direction, to point at it once it can."""
    offset = np.asarray(target, float)[:3] - np.asarray(position, float)[:3]
    beyond, over = _pointing_blocked(params, offset, heading_range, vertical)
    velocity = np.zeros(3)
    wanted_heading = float(np.arctan2(offset[1], offset[0]))
    if heading_range is not None:
        low, high = heading_range
        middle, half = 0.5 * (low + high), 0.5 * (high - low)
        if beyond:
            velocity[:2] = -facing(middle)
        bearing = float(wrap_angle(wanted_heading - middle))
        wanted_heading = middle + float(np.clip(bearing, -half, half))
    if over:
        velocity[2] = np.sign(offset[2])
    velocity = speed * unit(velocity)
    yaw_rate = turn_rate(params, float(wrap_angle(wanted_heading - heading)))
    return (velocity if vertical else velocity[:2]), yaw_rate


def insisting_side_heading(heading, position, target, heading_range=None):
    """The heading that puts the target to the side of the hand it is already nearer (the
    shorter turn), as an insisting participant wants it; the other side when that heading
    lies beyond `heading_range` (low, high) and the other's does not (an arm's wrist,
    which cannot turn a target ahead to its near side, but can to its far one)."""
    toward_target = unit(target[:2] - position[:2])
    side = 1.0 if heading_error(heading, position, target) >= 0.0 else -1.0
    bearing = np.arctan2(toward_target[1], toward_target[0])
    wanted = bearing - side * np.pi / 2
    if heading_range is not None:
        low, high = heading_range
        middle, half = 0.5 * (low + high), 0.5 * (high - low)
        other = bearing + side * np.pi / 2
        if (abs(wrap_angle(wanted - middle)) > half
                and abs(wrap_angle(other - middle)) <= half):
            return other
    return wanted


def insisting_motion(params, speed, position, heading, target, heading_range=None,
                     vertical=False):
    """`assist_motion` insisting: the velocity (2, or 3 with `vertical`) toward the target
    as far as the keys allow (its floor part `without_forward`), at `speed` slowing within
    `slow_radius`, so at most `speed` in all; the yaw rate turns the target to its side
    (`insisting_side_heading`; none with the target straight above or below)."""
    size = 3 if vertical else 2
    offset = np.asarray(target, float)[:size] - np.asarray(position, float)[:size]
    toward_target = unit(offset)
    slow = min(1.0, np.linalg.norm(offset) / params.slow_radius)
    floor = without_forward(toward_target[:2], heading)
    velocity = speed * slow * np.concatenate([floor, toward_target[2:]])
    if vertical and np.linalg.norm(offset[:2]) < 1e-9:
        return velocity, 0.0
    wanted_heading = insisting_side_heading(heading, position, target, heading_range)
    return velocity, turn_rate(params, float(wrap_angle(wanted_heading - heading)))


def drive_motion(params, speed, position, heading, target, vertical=False):
    """Teleop: the floor velocity (2) toward the target at `speed`, slowing within
    `slow_radius`, and the yaw rate that turns the hand to face it. `vertical`: the
    velocity (3) toward the target in 3-D, `slow_radius` on the 3-D distance, and no turn
    with the target straight above or below."""
    size = 3 if vertical else 2
    offset = np.asarray(target, float)[:size] - np.asarray(position, float)[:size]
    distance = np.linalg.norm(offset)
    if distance < 1e-9:
        return np.zeros(size), 0.0
    velocity = speed * min(1.0, distance / params.slow_radius) * offset / distance
    if vertical and np.linalg.norm(offset[:2]) < 1e-9:
        return velocity, 0.0
    return velocity, turn_rate(params, heading_error(heading, position, target))
