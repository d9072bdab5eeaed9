"""The `PoseDmpBank` system's state, in its two layouts, and its scratch.

Both layouts start with `[phase, held, p (3), q (4), eta (3)]` (`split_head`): `held` is
`STEPPING`, `ON_ROBOT` (PBP-Alt's lock) or `AT_START`, `p`, `q` the pose the last step
started from, `eta` a scaled angular velocity `tau omega`. Per goal, the K DMPs' stepped
arrays follow (`per_goal_arrays`: `[y' - p, z']` and `[e', z']`, 12 K numbers); compact,
the last step's phase and `z` (`compact_inputs`), from which `step_all` computes the
stepped arrays into a cache entry (docs/concepts/six-dof.md).
"""

import numpy as np

# `held`: stepping, holding at the robot (PBP-Alt's lock), at the starts.
STEPPING, ON_ROBOT, AT_START = 0.0, 1.0, 2.0
HEAD_SIZE = 12
COMPACT_TAIL_SIZE = 4


def split_head(vector):
    """Views: phase (1,), held (1,), p (3, 1), q (4, 1), eta (3, 1)."""
    return (vector[0:1], vector[1:2], vector[2:5].reshape(3, 1), vector[5:9].reshape(4, 1),
            vector[9:12].reshape(3, 1))


def per_goal_arrays(vector, goal_count):
    """Views of the stepped arrays `[y' - p, z']` and `[e', z']` (2, 3, K each) at the end
    of `vector`: a per-goal state, or the compact layout's cache entry (12 K numbers)."""
    start = len(vector) - 12 * goal_count
    return (vector[start:start + 6 * goal_count].reshape(2, 3, goal_count),
            vector[start + 6 * goal_count:].reshape(2, 3, goal_count))


def compact_inputs(vector):
    """Views of the compact layout's tail: the last step's phase (1,) and `z` (3, 1)."""
    return vector[HEAD_SIZE:HEAD_SIZE + 1], vector[HEAD_SIZE + 1:HEAD_SIZE + 4].reshape(3, 1)


class SteppedDmps:
    """The compact layout's cache entry: the K DMPs stepped from the state (`numbers`, laid
    out as a per-goal state's tail), and `J(e') z'` of goal `eta_goal` (`eta`; -1: none),
    which the selected reference's read computes and the next update reuses. Whoever
    rewrites `numbers` sets `eta_goal` to -1."""

    __slots__ = ("numbers", "eta_goal", "eta")

    def __init__(self, goal_count):
        self.numbers = np.zeros(12 * goal_count)
        self.eta_goal = -1
        self.eta = None


class PoseWorkspace:
    """Scratch of one Context: the two banks' workspaces, the velocities the step starts
    from (`column`, `eta_column`: the followed DMP's; `velocities`, `eta`: every DMP's),
    and whether the goals were recomputed since the last step (`goals_changed`)."""

    __slots__ = ("position", "orientation", "phase", "column", "eta_column", "velocities",
                 "orientations", "eta", "goals_changed")

    def __init__(self, position_bank, orientation_bank):
        k = position_bank.goal_count
        self.position = position_bank.make_workspace()
        self.orientation = orientation_bank.make_workspace()
        self.phase = np.empty(1)
        self.column = np.empty((3, 1))
        self.eta_column = np.empty((3, 1))
        self.velocities = np.empty((3, k))
        self.orientations = np.empty((4, k))
        self.eta = np.empty((3, k))
        self.goals_changed = True


def step_all(positions, orientations, shared_basis, phase, robot, q, z, eta, goals, period,
             stepped, log_state, workspace):
    """Every DMP's step from the phase, the measured pose `robot` (3, 1), `q` (4, 1) and
    the scaled velocities `z`, `eta` ((3, 1) for all, or (3, K)), toward `goals` (7, K),
    into `stepped` and `log_state` (2, 3, K); with `shared_basis` the orientation step
    contracts the position step's basis."""
    unchanged = not workspace.goals_changed
    positions.stepped_from_one_into(phase, robot, z, goals[:3], period, stepped,
                                    workspace.position, goals_unchanged=unchanged)
    basis = (workspace.position.basis, workspace.position.lam) if shared_basis else None
    orientations.log_step_into(phase, q, eta, goals[3:], period, workspace.phase, log_state,
                               workspace.orientation, goals_unchanged=unchanged, basis=basis)
    workspace.goals_changed = False


def hold_into(held, robot, z, starts, stepped):
    """The compact cache's stepped positions while held: the starts at the start (from
    `p = 0`), the hand's position on the robot; every DMP's `z` the held one."""
    offsets, velocities = stepped
    if held == AT_START:
        np.subtract(starts, robot, out=offsets)
    else:
        offsets.fill(0.0)
    velocities[...] = z
