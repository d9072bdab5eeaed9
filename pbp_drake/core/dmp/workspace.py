"""Scratch memory of one caller of a `DmpBank`: what makes the bank's step allocation-free.

The bank itself is an immutable model; every array a step writes to lives in a
`DmpWorkspace` its caller owns (`bank.make_workspace()`), one per thread or per Drake
Context, so callers stepping one bank from different threads or contexts cannot corrupt
each other. A workspace holds nothing between calls: any call may overwrite all of it, and a
copy of one is as good as a fresh one (so Drake's cloning of a Context, which deep-copies its
cache values, is correct without help). Its fields are plain arrays, no views of each other,
for the same reason: `copy.deepcopy` would turn views into separate arrays.
"""

import numpy as np


class DmpWorkspace:
    """Work arrays for a bank of K DMPs in D dimensions with N basis functions.

    Attributes:
        psi: (N,) the basis at one phase.
        coefficients: (D,) the shared-weights forcing shape.
        shape: (D, K) the per-goal forcing shape.
        attractor: (D, K) the moving attractors.
        offset: (D, K) positions minus attractors (used by `advance_into`).
        work: (D, K) the last pass of a step.
        alpha_goal, alpha_constant: (D, 1) the affine attractor's coefficients.
        column: (D, 1) one position minus `alpha_constant`.
    """

    __slots__ = ("dimension", "goal_count", "basis_count", "psi", "coefficients", "shape",
                 "attractor", "offset", "work", "alpha_goal", "alpha_constant", "column")

    def __init__(self, dimension, goal_count, basis_count):
        d, k, n = dimension, goal_count, basis_count
        self.dimension, self.goal_count, self.basis_count = d, k, n
        self.psi = np.empty(n)
        self.coefficients = np.empty(d)
        self.shape = np.empty((d, k))
        self.attractor = np.empty((d, k))
        self.offset = np.empty((d, k))
        self.work = np.empty((d, k))
        self.alpha_goal = np.empty((d, 1))
        self.alpha_constant = np.empty((d, 1))
        self.column = np.empty((d, 1))

