"""The `PoseDmpBank` system's state, in its two layouts, and its scratch.

Both layouts start with the same twelve numbers (`split_head`): `[phase, held, p (3),
q (4), eta (3)]`, the phase after the last step, whether the DMPs are stepping or held
(`STEPPING`, `ON_ROBOT`: PBP-Alt's lock, `AT_START`), the measured pose the last step
started from, and a scaled angular velocity `tau omega` (3).

- **Per goal** (`compact=False`): then the K DMPs' stepped arrays (`per_goal_arrays`): the
  position DMPs' offsets `y' - p` and scaled velocities `z'` (2, 3, K), and the orientation
  DMPs' log coordinates `(e', z')` (2, 3, K). 12 K numbers, which Drake copies twice at
  each update. `eta` is the held angular velocity (the hand's, locked; 0 at the start).
- **Compact** (`compact=True`): then what the last step started from (`compact_inputs`):
  its phase and the linear scaled velocity `z` (3); `eta` is the angular one. 16 numbers
  whatever K. It holds only when every DMP steps from the followed DMP's velocities
  (`followed_goal` connected), for then the K stepped DMPs are a function of these inputs
  and the goals: the system computes them into a cache entry (`step_all`, the same call
  as the per-goal update makes), once per state, when first read.
"""

import numpy as np

# `held`: stepping, holding at the robot (PBP-Alt's lock), at the starts.
STEPPING, ON_ROBOT, AT_START = 0.0, 1.0, 2.0
HEAD_SIZE = 12
COMPACT_TAIL_SIZE = 4


def state_size(goal_count, compact):
    """The length of the state vector of either layout (module docstring)."""
    return HEAD_SIZE + (COMPACT_TAIL_SIZE if compact else 12 * goal_count)


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
    """The compact layout's cache entry: the K DMPs stepped from the state (`numbers`,
    12 K, laid out as a per-goal state's tail, `per_goal_arrays`), and `J(e') z'` of one of
    them (`eta`, 3 floats, of goal `eta_goal`; -1: none yet): the selected reference's
    read computes it, and the next update, which needs the followed DMP's, takes it when
    they are the same goal (the normal case), as it takes these numbers, not computing
    them twice. Whoever rewrites `numbers` sets `eta_goal` to -1."""

    __slots__ = ("numbers", "eta_goal", "eta")

    def __init__(self, goal_count):
        self.numbers = np.zeros(12 * goal_count)
        self.eta_goal = -1
        self.eta = None


class PoseWorkspace:
    """Scratch of one Context: the two banks' workspaces, a phase, the linear velocities
    the step starts from (`column`, the followed DMP's; `velocities`, every DMP's when no
    followed goal is connected), the angular ones likewise (`eta_column`; `eta`, with
    `orientations` the orientation readout's arrays), and whether the goals were
    recomputed since the last step (`goals_changed`: if not, the banks reuse what they
    derived from the goals, without comparing K goals)."""

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
    into `stepped` and `log_state` (2, 3, K). The banks reuse what they derived from the
    goals while the goals cache entry has not been recomputed (they vouch for nothing
    else); with `shared_basis` the orientation step contracts the position step's basis."""
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
