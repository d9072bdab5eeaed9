"""The peers: the same step with `pydmps` and `movement_primitives`, one object per goal as
their APIs intend, re-integrated from the robot's position as PBP does, and
`movement_primitives` with every goal stacked into one K*D-dimensional DMP.

Both libraries are optional (pip install -e '.[bench]'; movement_primitives pulls in SciPy
and pytransform3d), so each is imported only inside the factory that times it.
"""

import importlib

import numpy as np

from pbp_drake_bench.cases import BASIS, DT
from pbp_drake.core.dmp import DmpSettings


def _peer_weights(case, k):
    return case.shared_weights if case.weights is None else case.weights[k]


def pydmps_step(case):
    """pydmps, one `DMPs_discrete` per goal, each re-integrated from the robot's position
    (its `.y` is writable) and stepped once."""
    import pydmps  # deferred on purpose: optional (see the module docstring)

    centres, widths = DmpSettings(basis_count=BASIS).basis()
    dmps = []
    for k in range(case.goal_count):
        dmp = pydmps.DMPs_discrete(n_dmps=case.dimension, n_bfs=BASIS, dt=DT,
                                   y0=case.start.copy(), goal=case.goals[k].copy(),
                                   w=_peer_weights(case, k).T.copy(),
                                   ax=DmpSettings().alpha_x)
        dmp.c, dmp.h = centres.copy(), widths.copy()
        dmps.append(dmp)
    robot = case.robot

    def step():
        for dmp in dmps:
            dmp.y[:] = robot
            dmp.step()
    return step


def movement_primitives_step(case):
    """movement_primitives, one `DMP` per goal; `step` ignores the state passed in, so the
    robot's position is written into its `current_y` by hand, as a PBP user must."""
    from movement_primitives.dmp import DMP  # deferred on purpose: optional, pulls SciPy

    dmps = []
    zeros = np.zeros(case.dimension)
    for k in range(case.goal_count):
        dmp = DMP(n_dims=case.dimension, execution_time=1.0, dt=DT,
                  n_weights_per_dim=BASIS, int_dt=DT)
        dmp.configure(start_y=case.start.copy(), goal_y=case.goals[k].copy())
        dmp.set_weights(_peer_weights(case, k).T.reshape(-1).copy())
        dmp.step(case.start.copy(), zeros)
        dmps.append(dmp)
    robot = case.robot

    def step():
        for dmp in dmps:
            dmp.current_y[:] = robot
            dmp.step(robot, zeros)
    return step


def movement_primitives_stacked_step(case):
    """movement_primitives with every goal stacked into one K*D-dimensional DMP: the fastest
    trick its user has (distinct weights per goal come for free; shared ones are tiled)."""
    from movement_primitives.dmp import DMP  # deferred on purpose: optional, pulls SciPy

    k, d = case.goal_count, case.dimension
    dmp = DMP(n_dims=k * d, execution_time=1.0, dt=DT, n_weights_per_dim=BASIS, int_dt=DT)
    dmp.configure(start_y=np.tile(case.start, k), goal_y=case.goals.reshape(-1).copy())
    if case.weights is None:
        weights = np.tile(case.shared_weights.T, (k, 1))
    else:
        weights = case.weights.transpose(0, 2, 1).reshape(k * d, BASIS)
    dmp.set_weights(weights.reshape(-1).copy())
    robot = np.tile(case.robot, k)
    zeros = np.zeros(k * d)
    dmp.step(robot, zeros)

    def step():
        dmp.current_y[:] = robot
        dmp.step(robot, zeros)
    return step


def available(module):
    """Whether an optional peer library imports."""
    try:
        importlib.import_module(module)
        return True
    except ImportError:
        return False
