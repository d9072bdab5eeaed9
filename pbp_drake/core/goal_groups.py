"""Goals that cannot be told apart act as one, in pure NumPy: the group (the fewest most
probable goals holding `group_mass`), the point the robot heads for (their
probability-weighted mean; for poses, `pose_group_target`, with the chordal mean
orientation) and when it commits to the estimator's selected goal, showing `NO_GOAL`
until then. The rules and why: docs/concepts/goal-estimators.md, "Many goals: goal
groups"."""

import typing

import numpy as np

from pbp_drake.core.quaternion import angle_between

#: The shown goal while the robot follows a group and has not committed.
NO_GOAL = -1


class GroupTarget(typing.NamedTuple):
    """What `group_target` returns: the point the robot heads for (3; a pose (7) from
    `pose_group_target`), the index shown (`NO_GOAL` while uncommitted) and the group's
    size."""

    point: np.ndarray
    shown: int
    size: int


def _most_probable(probabilities, mass):
    """The fewest most probable goals that hold `mass`, most probable first: the top m
    found by partition (O(K)), m growing fourfold until they hold it, then sorted."""
    count = len(probabilities)
    m = min(count, 64)
    while True:
        top = (np.arange(count) if m == count else
               np.argpartition(-probabilities, m - 1)[:m])
        top = top[np.argsort(-probabilities[top], kind="stable")]
        held = np.cumsum(probabilities[top])
        if held[-1] >= mass or m == count:
            return top[:int(np.searchsorted(held, mass)) + 1]
        m = min(count, 4 * m)


def _members(probabilities, selected, group_mass, commit_probability, committed):
    """The members of the group (most probable first), or None when the robot commits to
    `selected` whatever the group: its probability is high enough, or it was committed to."""
    best = int(np.argmax(probabilities))
    if probabilities[best] >= commit_probability or committed == selected:
        return None
    return _most_probable(probabilities, group_mass * float(probabilities.sum()))


def group_target(goals, probabilities, selected, group_mass, commit_radius,
                 commit_probability, hand=None, committed=NO_GOAL):
    """The `GroupTarget` of `goals` (K, 3) under `probabilities` (K), the estimator's
    `selected` goal committed to when the group allows (the docs page): `hand` (3) is
    the hand's position (None: not read), `committed` the goal committed to before
    (`NO_GOAL`: none)."""
    members = _members(probabilities, selected, group_mass, commit_probability, committed)
    if members is None:
        return GroupTarget(goals[selected].copy(), selected, 1)
    weights = probabilities[members]
    point = weights @ goals[members] / weights.sum()
    spread = float(np.max(np.linalg.norm(goals[members] - point, axis=1)))
    arrived = hand is not None and float(np.linalg.norm(hand - point)) <= commit_radius
    return _committed_or_group(goals[selected], point, selected, len(members),
                               spread <= commit_radius or arrived)


def pose_group_target(poses, probabilities, selected, group_mass, commit_radius,
                      commit_probability, metres_per_radian, hand=None, committed=NO_GOAL):
    """`group_target` for pose goals: `poses` (K, 7) rows `[x, y, z, qw, qx, qy, qz]`
    (unit quaternions), the point a pose (7), distances the pose error
    `|p - g| + L angle(q, q_g)` with `L = metres_per_radian`; `hand` the hand's pose (7) or
    None."""
    members = _members(probabilities, selected, group_mass, commit_probability, committed)
    goal = poses[selected]
    # The grasps within the radius of the selected one act as one with it.
    if members is None or float(probabilities[_pose_errors(
            poses, goal, metres_per_radian) <= commit_radius].sum()) >= commit_probability:
        return GroupTarget(goal.copy(), selected, 1)
    weights = probabilities[members] / probabilities[members].sum()
    rows = poses[members]
    position = weights @ rows[:, :3]
    # On the most probable member's hemisphere (q and -q are one orientation).
    signs = np.where(rows[:, 3:] @ rows[0, 3:] < 0.0, -1.0, 1.0)
    orientation = (weights * signs) @ rows[:, 3:]
    norm = float(np.linalg.norm(orientation))
    orientation = orientation / norm if norm > 1e-9 else rows[0, 3:].copy()
    point = np.concatenate([position, orientation])
    spread = float(np.max(_pose_errors(rows, point, metres_per_radian)))
    # At the group's pose, or already at the selected grasp (the grasps of one object
    # differ in orientation: a group of them can hold its point away from every grasp).
    arrived = hand is not None and float(np.min(_pose_errors(
        np.vstack([point, goal]), hand, metres_per_radian))) <= commit_radius
    return _committed_or_group(goal, point, selected, len(members),
                               spread <= commit_radius or arrived)


def _pose_errors(poses, pose, metres_per_radian):
    """`|p - g| + L angle(q, q_g)` of each of `poses` (N, 7) from `pose` (7)."""
    return (np.linalg.norm(poses[:, :3] - pose[:3], axis=1) + metres_per_radian
            * angle_between(poses[:, 3:].T, np.asarray(pose[3:])[:, np.newaxis]))


def _committed_or_group(goal, point, selected, size, together):
    """The robot commits to `selected` (at `goal`) when the group is one goal or its goals
    act as one (`together`), else heads for the group's `point` showing `NO_GOAL`."""
    if size == 1 or together:
        return GroupTarget(np.array(goal, dtype=float), selected, size)
    return GroupTarget(point, NO_GOAL, size)
