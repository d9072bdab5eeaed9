"""Goals that cannot be told apart act as one, in pure NumPy.

With many candidate goals a goal estimator's probabilities spread over the goals near
where the operator points; following the single most probable of them takes the robot to
a neighbour of the intended goal about as often as to the goal, and the operator spends
the run correcting it. Here the robot follows the group instead, coarse to fine:

- **The group** is the smallest set of the most probable goals that holds `group_mass` of
  the probability (a credible set; O(K) partitions and a sort of the group's members).
- **Its point** is the group's probability-weighted mean goal: the DMP of the selected goal
  is steered to it, so the robot heads into the region the operator means.
- **Commitment.** The robot commits to the estimator's selected goal (its hysteresis
  kept) and shows it once the group is one goal, or its goals lie within `commit_radius`
  of their point (they act as one), or the most probable goal holds `commit_probability`,
  or the hand has reached the group's point (within `commit_radius`: heading into the
  region is done, and the best guess is shown for the operator to confirm or correct).
  Until then it shows no goal: `NO_GOAL` is the shown index. A commitment holds while the
  estimator selects the same goal (`committed`), so that the robot leaving the group's
  point for the goal does not undo it.

As the hand nears the group, goals off its heading fall out of it and the group narrows to
the goal meant; a goal that stays ambiguous (two goals in line) is decided by the
operator's correction, as with a single goal.
"""

import typing

import numpy as np

#: The shown goal while the robot follows a group and has not committed.
NO_GOAL = -1


class GroupTarget(typing.NamedTuple):
    """What `group_target` returns: the point the robot heads for (3), the index shown
    (`NO_GOAL` while uncommitted) and the group's size."""

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


def group_target(goals, probabilities, selected, group_mass, commit_radius,
                 commit_probability, hand=None, committed=NO_GOAL):
    """The `GroupTarget` of `goals` (K, 3) under `probabilities` (K), the estimator's
    `selected` goal committed to when the group allows (module docstring): `hand` (3) is
    the hand's position (None: not read), `committed` the goal committed to before
    (`NO_GOAL`: none)."""
    best = int(np.argmax(probabilities))
    if probabilities[best] >= commit_probability or committed == selected:
        return GroupTarget(goals[selected].copy(), selected, 1)
    members = _most_probable(probabilities, group_mass * float(probabilities.sum()))
    size = len(members)
    weights = probabilities[members]
    point = weights @ goals[members] / weights.sum()
    spread = float(np.max(np.linalg.norm(goals[members] - point, axis=1)))
    arrived = hand is not None and float(np.linalg.norm(hand - point)) <= commit_radius
    if size == 1 or spread <= commit_radius or arrived:
        return GroupTarget(goals[selected].copy(), selected, size)
    return GroupTarget(point, NO_GOAL, size)
