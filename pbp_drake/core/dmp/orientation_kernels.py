"""The unit-quaternion math of `pbp_drake.core.quaternion`, written into preallocated
`(4, K)` and `(3, K)` arrays for the orientation bank's step: no allocation per step, and a
fixed number of passes over K (no loop over goals).

`pbp_drake.core.quaternion` stays the readable version (and the single `OrientationDmp`'s);
`tests/core/test_orientation_bank_equivalence.py` holds the two to 1e-12. The scratch arrays
live in an `OrientationWorkspace` the caller owns, one per thread or Drake Context, as the
position bank's `DmpWorkspace`; it holds nothing between calls but the
start errors of the last goals, which it recomputes when the goals or the bank change.
"""

import numpy as np

from pbp_drake.core.quaternion import SERIES_BELOW

# The smallest denominator: every closed form is evaluated at every angle, with its
# denominator kept at least this (so 0 / 0 never happens), and the series replace it where
# the angle is small. Computing both and selecting with `np.copyto(..., where=)` is many
# times faster than ufuncs with a `where=` mask that varies from goal to goal.
SMALLEST = 1e-300
# Hamilton's product `p q` by rows of the result: (index in p, index in q, sign).
_PRODUCT_TERMS = (
    ((0, 0, 1), (1, 1, -1), (2, 2, -1), (3, 3, -1)),
    ((0, 1, 1), (1, 0, 1), (2, 3, 1), (3, 2, -1)),
    ((0, 2, 1), (1, 3, -1), (2, 0, 1), (3, 1, 1)),
    ((0, 3, 1), (1, 2, 1), (2, 1, -1), (3, 0, 1)),
)
_CONJUGATION = np.diag([1.0, -1.0, -1.0, -1.0])
_CONJUGATION.setflags(write=False)


class OrientationWorkspace:
    """Work arrays for the step of K orientation DMPs with N basis functions.

    Attributes:
        error_quaternions, product: (4, K) `q g*`, and the new orientations before signing.
        start_errors, amplitude: (3, K) `e0 = Log(q0 g*)`, and `-e0` (1 where unscaled).
        errors, log_velocity: (3, K) `e` and `z = J(e)^-1 eta`.
        new_errors, new_log_velocity: (3, K) `e'` and `z'`.
        cross, double_cross, work: (3, K) scratch.
        angle, sine, cosine, coefficient, second, row: (K,) per-goal numbers.
        small, large: (K,) masks. shape: (2, 3, K) forcing shapes of distinct weights.
        goals_of_start_errors, starts_of_start_errors: the goals (a copy) and the bank's
            starts (the array itself) that `start_errors` and `amplitude` were computed for:
            they depend on nothing else, so a step to unchanged goals reuses them. A copied
            workspace has copied starts, which are not the bank's, and so recomputes.
    """

    __slots__ = ("goal_count", "basis_count", "error_quaternions", "product", "start_errors",
                 "amplitude", "errors", "log_velocity", "new_errors", "new_log_velocity",
                 "cross", "double_cross", "work", "angle", "sine", "cosine", "coefficient",
                 "second", "row", "small", "large", "shape", "goals_of_start_errors",
                 "starts_of_start_errors")

    def __init__(self, goal_count, basis_count):
        k = goal_count
        self.goal_count, self.basis_count = goal_count, basis_count
        for name in ("error_quaternions", "product"):
            setattr(self, name, np.empty((4, k)))
        for name in ("start_errors", "amplitude", "errors", "log_velocity", "new_errors",
                     "new_log_velocity", "cross", "double_cross", "work"):
            setattr(self, name, np.empty((3, k)))
        for name in ("angle", "sine", "cosine", "coefficient", "second", "row"):
            setattr(self, name, np.empty(k))
        self.small = np.empty(k, bool)
        self.large = np.empty(k, bool)
        self.shape = np.empty((2, 3, k))
        self.goals_of_start_errors = np.full((4, k), np.nan)
        self.starts_of_start_errors = None


def left_product_matrix(quaternion):
    """The 4x4 `L(p)` with `p q = L(p) q`, for one quaternion `(4,)` or `(4, 1)`."""
    w, x, y, z = np.asarray(quaternion, dtype=float).reshape(4)
    return np.array([[w, -x, -y, -z], [x, w, -z, y], [y, z, w, -x], [z, -y, x, w]])


def error_quaternions_into(orientations, goals, out, row):
    """`out = q g*` (4, K) for orientations `(4, 1)` (one BLAS product) or `(4, K)`."""
    if orientations.shape[1] == 1:
        np.dot(left_product_matrix(orientations) @ _CONJUGATION, goals, out=out)
        return
    for target, terms in zip(out, _PRODUCT_TERMS):
        for position, (left, right, sign) in enumerate(terms):
            # The conjugate of g flips the sign of its vector part (right index > 0).
            sign = sign if right == 0 else -sign
            if position == 0:
                np.multiply(orientations[left], goals[right], out=target)
                if sign < 0:
                    np.negative(target, out=target)
                continue
            np.multiply(orientations[left], goals[right], out=row)
            if sign > 0:
                target += row
            else:
                target -= row


def product_into(left, right, out, row):
    """`out = left right`, Hamilton's product of `(4, K)` arrays (`out` neither of them)."""
    for target, terms in zip(out, _PRODUCT_TERMS):
        for position, (i, j, sign) in enumerate(terms):
            if position == 0:
                np.multiply(left[i], right[j], out=target)  # every row's first term is +
                continue
            np.multiply(left[i], right[j], out=row)
            if sign > 0:
                target += row
            else:
                target -= row


def log_into(quaternions, out, workspace):
    """`out = Log(q)` (3, K), the same for `q` and `-q`; leaves the angle, `sin(angle/2)`
    and `cos(angle/2) = |w|` in the workspace's `angle`, `sine` and `cosine`."""
    ws = workspace
    vector = quaternions[1:]
    np.multiply(vector, vector, out=ws.work)
    np.sum(ws.work, axis=0, out=ws.sine)
    np.sqrt(ws.sine, out=ws.sine)
    np.abs(quaternions[0], out=ws.cosine)
    np.arctan2(ws.sine, ws.cosine, out=ws.angle)
    ws.angle *= 2.0
    # angle / sin(angle / 2): accurate down to the smallest sines (atan2 is), and 0 for the
    # identity, whose vector part is 0 anyway.
    np.maximum(ws.sine, SMALLEST, out=ws.row)
    np.divide(ws.angle, ws.row, out=ws.coefficient)
    # The hemisphere w >= 0: the sign of w, or at w = 0 exactly, of x, then y, then z.
    np.sign(quaternions[0], out=ws.row)
    if not ws.row.all():
        for component in vector:
            np.copyto(ws.row, np.sign(component), where=ws.row == 0.0)
    ws.coefficient *= ws.row
    np.multiply(vector, ws.coefficient, out=out)


def exp_into(rotation_vectors, out, workspace):
    """`out = Exp(r)` (4, K); leaves `|r|` in `angle`, `sin(|r|/2)` in `sine`, its
    `cos` in `cosine` and `sin(|r|/2) / |r|` (0 at 0) in `coefficient`."""
    ws = workspace
    np.multiply(rotation_vectors, rotation_vectors, out=ws.work)
    np.sum(ws.work, axis=0, out=ws.angle)
    np.sqrt(ws.angle, out=ws.angle)
    np.multiply(ws.angle, 0.5, out=ws.row)
    np.sin(ws.row, out=ws.sine)
    np.cos(ws.row, out=ws.cosine)
    out[0] = ws.cosine
    np.maximum(ws.angle, SMALLEST, out=ws.row)
    np.divide(ws.sine, ws.row, out=ws.coefficient)
    np.multiply(rotation_vectors, ws.coefficient, out=out[1:])


def cross_into(first, second, out, row):
    """`out = first x second` for `(3, K)` arrays (`out` neither of them)."""
    for index in range(3):
        a, b = (index + 1) % 3, (index + 2) % 3
        np.multiply(first[a], second[b], out=out[index])
        np.multiply(first[b], second[a], out=row)
        out[index] -= row


def inverse_jacobian_into(rotation_vectors, vectors, out, workspace):
    """`out = J(r)^-1 v` (3, K), with `angle`, `sine` and `cosine` of `r` from `log_into`
    (no trigonometry: `(t/2) cot(t/2) = (t/2) cos / sin` from the quaternion)."""
    ws = workspace
    coefficient, square, closed = ws.coefficient, ws.second, ws.row
    np.multiply(ws.angle, ws.angle, out=square)
    # c = (1 - (t/2) cot(t/2)) / t^2; its series 1/12 + t^2/720 + t^4/30240 when small.
    np.multiply(square, 1.0 / 30240.0, out=coefficient)
    coefficient += 1.0 / 720.0
    coefficient *= square
    coefficient += 1.0 / 12.0
    np.maximum(ws.sine, SMALLEST, out=closed)
    np.divide(ws.cosine, closed, out=closed)
    closed *= ws.angle
    closed *= -0.5
    closed += 1.0
    np.maximum(square, SMALLEST, out=square)
    closed /= square
    np.greater_equal(ws.angle, SERIES_BELOW, out=ws.large)
    np.copyto(coefficient, closed, where=ws.large)
    _jacobian_terms_into(rotation_vectors, vectors, -0.5, coefficient, out, ws)


def jacobian_into(rotation_vectors, vectors, out, workspace):
    """`out = J(r) v` (3, K), with `angle`, `sine`, `cosine` and `coefficient` of `r` from
    `exp_into`: `a = (1 - cos t)/t^2 = 2 (sin(t/2)/t)^2`, `b = (t - sin t)/t^3`."""
    ws = workspace
    a, b, closed, cube = ws.coefficient, ws.row, ws.sine, ws.second
    np.multiply(a, a, out=a)
    a *= 2.0
    np.multiply(ws.angle, ws.angle, out=cube)
    # b's series 1/6 - t^2/120 + t^4/5040 when small, else (t - 2 sin(t/2) cos(t/2)) / t^3.
    np.multiply(cube, 1.0 / 5040.0, out=b)
    b -= 1.0 / 120.0
    b *= cube
    b += 1.0 / 6.0
    closed *= ws.cosine
    closed *= -2.0
    closed += ws.angle
    cube *= ws.angle
    np.maximum(cube, SMALLEST, out=cube)
    closed /= cube
    np.greater_equal(ws.angle, SERIES_BELOW, out=ws.large)
    np.copyto(b, closed, where=ws.large)
    _jacobian_terms_into(rotation_vectors, vectors, a, b, out, ws)


def _jacobian_terms_into(rotation_vectors, vectors, first, second, out, workspace):
    """`out = v + first (r x v) + second (r x (r x v))`, `first` a number or `(K,)`."""
    ws = workspace
    cross_into(rotation_vectors, vectors, ws.cross, ws.cosine)
    cross_into(rotation_vectors, ws.cross, ws.double_cross, ws.cosine)
    np.multiply(ws.double_cross, second, out=out)
    np.multiply(ws.cross, first, out=ws.cross)
    out += ws.cross
    out += vectors
