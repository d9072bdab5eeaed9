"""Scratch memory of one caller of a `DmpBankModel`: what makes the bank's step allocation-free.

Every array a step writes to lives in a `DmpWorkspace` its caller owns
(`bank.make_workspace()`), one per thread or per Drake Context. A workspace holds nothing
between calls (but for a caller that vouches that its goals have not changed:
`scaled_weights`), so a copy of one is as good as a fresh one: Drake's cloning of a
Context, which deep-copies its cache values, is correct without help. Its fields are plain
arrays, no views of each other, for the same reason (`copy.deepcopy` would turn views into
separate arrays)."""

import numpy as np


class DmpWorkspace:
    """Work arrays for a bank of K DMPs in D dimensions with N basis functions.

    Attributes:
        phases, scale: (2, 1) the step's two phases, and their basis's scale.
        psi: (2, N) the basis at the two phases; basis: (2, N) its two combinations.
        lam: (2, 1) the phases' two combinations.
        coefficients: (2, D) the shared-weights forcing shapes.
        shape: (2, D, K) the per-goal forcing shapes (or scratch).
        amplitude: (D, K) `g - y0`; work: (D, K) `p - g`, and the last pass of a step.
        dp, dz: (D, K) the step's attractor terms (used by `advance_into`).
        alpha, beta, column: (2, D, 1) the affine terms' coefficients, and scratch.
        scaled_weights, scaled_rows: distinct weights times `amplitude`, and which rows
            are (None until a caller vouches for unchanged goals, see
            `BankStep.attractor_terms_into`): the one thing a workspace may keep between
            calls, and only for the caller that vouches.
        goal_terms, goal_terms_dt: `-(Phi00 - 1, Phi10) g` (2, D, K) of those goals for
            steps of `goal_terms_dt` (`BankStep.stepped_from_one_into`), kept likewise.
    """

    __slots__ = ("dimension", "goal_count", "basis_count", "phases", "scale", "psi", "basis",
                 "lam", "coefficients", "shape", "amplitude", "work", "dp", "dz", "alpha",
                 "beta", "column", "scaled_weights", "scaled_rows", "goal_terms",
                 "goal_terms_dt")

    def __init__(self, dimension, goal_count, basis_count):
        d, k, n = dimension, goal_count, basis_count
        self.dimension, self.goal_count, self.basis_count = d, k, n
        self.phases = np.empty((2, 1))
        self.scale = np.empty((2, 1))
        self.psi = np.empty((2, n))
        self.basis = np.empty((2, n))
        self.lam = np.empty((2, 1))
        self.coefficients = np.empty((2, d))
        self.shape = np.empty((2, d, k))
        self.amplitude = np.empty((d, k))
        self.work = np.empty((d, k))
        self.dp = np.empty((d, k))
        self.dz = np.empty((d, k))
        self.alpha = np.empty((2, d, 1))
        self.beta = np.empty((2, d, 1))
        self.column = np.empty((2, d, 1))
        self.scaled_weights = self.scaled_rows = None
        self.goal_terms, self.goal_terms_dt = None, None
