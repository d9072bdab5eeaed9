"""The unit-quaternion math of `pbp_drake.core.quaternion`, written into preallocated
`(4, K)` and `(3, K)` arrays for the orientation bank's step: no allocation per step, and a
fixed number of passes over K (no loop over goals). `pbp_drake.core.quaternion` stays the
readable version; `tests/core/test_orientation_bank_equivalence.py` holds the two to 1e-12.
The scratch arrays live in an `OrientationWorkspace` the caller owns, one per thread or
Drake Context. The forms the kernels take for speed (the Jacobians read off the half
angle's sine and cosine, one `tan(t/4)` for both, the series only where an angle is small):
docs/concepts/dmp.md, "Orientation DMPs"."""

import math

import numpy as np

from pbp_drake.core.quaternion import SERIES_BELOW

# The smallest denominator: every closed form is evaluated at every angle, its denominator
# kept at least this (no 0 / 0), and the series replace it where the angle is small (faster
# than ufuncs with a `where=` mask that varies from goal to goal).
SMALLEST = 1e-300
# Hamilton's product `p q` by rows of the result: (index in p, index in q, sign).
_PRODUCT_TERMS = (
    ((0, 0, 1), (1, 1, -1), (2, 2, -1), (3, 3, -1)),
    ((0, 1, 1), (1, 0, 1), (2, 3, 1), (3, 2, -1)),
    ((0, 2, 1), (1, 3, -1), (2, 0, 1), (3, 1, 1)),
    ((0, 3, 1), (1, 2, 1), (2, 1, -1), (3, 0, 1)),
)


class OrientationWorkspace:
    """Work arrays for the step of K orientation DMPs with N basis functions.

    Attributes:
        error_quaternions, product: (4, K) `q g*`, and the new orientations before signing.
        start_errors, amplitude: (3, K) `e0 = Log(q0 g*)`, and `-e0` (1 where unscaled).
        log_state: (2, 3, K) `e` and `z = J(e)^-1 eta` (properties `errors`,
            `log_velocity` give its two halves).
        new_log_state: (2, 3, K) `e'` and `z'` (`new_errors`, `new_log_velocity`).
        cross, work: (3, K) scratch. cross_dot: (4, K) `r x v` and `r.v` for one `v`.
        angle, sine, cosine, ratio, first, second, coefficient, dot, row: (K,) per goal.
        small: (K,) mask.
        fused: (15, K) the fused step's rows (`orientation_log_step`); its rows 9-14 are
            `shape` (property), (2, 3, K) forcing shapes of distinct weights (scratch).
        scaled_weights, scaled_rows: distinct weights `(N, 3 K)` times `-e0`, and which of
            their rows are, for the start errors' goals (None until the fused step needs
            them; `contraction.scaled_weights`).
        goals_of_start_errors, starts_of_start_errors: the goals (a copy) and the bank's
            starts (the array itself) that `start_errors` and `amplitude` were computed for,
            reused while they stay (a copied workspace's starts are not the bank's).

    The halves of `log_state`, and `shape`, are properties, not views, as in `DmpWorkspace`.
    """

    __slots__ = ("goal_count", "basis_count", "error_quaternions", "product", "start_errors",
                 "amplitude", "log_state", "new_log_state", "cross", "work", "cross_dot",
                 "angle", "sine", "cosine", "ratio", "first", "second", "coefficient", "dot",
                 "row", "small", "fused", "scaled_weights", "scaled_rows",
                 "goals_of_start_errors", "starts_of_start_errors")

    def __init__(self, goal_count, basis_count):
        k = goal_count
        self.goal_count, self.basis_count = goal_count, basis_count
        for name in ("error_quaternions", "product", "cross_dot"):
            setattr(self, name, np.empty((4, k)))
        for name in ("start_errors", "amplitude", "cross", "work"):
            setattr(self, name, np.empty((3, k)))
        for name in ("angle", "sine", "cosine", "ratio", "first", "second", "coefficient",
                     "dot", "row"):
            setattr(self, name, np.empty(k))
        self.log_state = np.empty((2, 3, k))
        self.new_log_state = np.empty((2, 3, k))
        self.small = np.empty(k, bool)
        self.fused = np.empty((15, k))
        self.scaled_weights = self.scaled_rows = None
        self.goals_of_start_errors = np.full((4, k), np.nan)
        self.starts_of_start_errors = None

    @property
    def shape(self):
        return self.fused[9:].reshape(2, 3, self.goal_count)

    @property
    def errors(self):
        return self.log_state[0]

    @property
    def log_velocity(self):
        return self.log_state[1]

    @property
    def new_errors(self):
        return self.new_log_state[0]

    @property
    def new_log_velocity(self):
        return self.new_log_state[1]


def conjugate_product_rows(orientation):
    """The rows (4 lists of 4 numbers) of the matrix `A` with `A g = q g*`, for one
    orientation `(4, 1)`: `L(q) diag(1, -1, -1, -1)`, `L(q)`'s columns 1-3 negated."""
    w, x, y, z = orientation[:, 0].tolist()
    return [[w, x, y, z], [x, -w, z, -y], [y, -z, -w, x], [z, y, -x, -w]]


def error_quaternions_into(orientations, goals, out, row):
    """`out = q g*` (4, K) for orientations `(4, 1)` (one BLAS product) or `(4, K)`."""
    if orientations.shape[1] == 1:
        np.dot(np.array(conjugate_product_rows(orientations)), goals, out=out)
        return
    product_into(orientations, goals, out, row, conjugate_right=True)


def product_into(left, right, out, row, conjugate_right=False):
    """`out = left right`, Hamilton's product of `(4, K)` arrays (`out` neither of them);
    with `conjugate_right`, `left right*`."""
    for target, terms in zip(out, _PRODUCT_TERMS):
        for position, (i, j, sign) in enumerate(terms):
            # The conjugate flips the sign of the vector part (j > 0).
            sign = -sign if conjugate_right and j > 0 else sign
            if position == 0:
                np.multiply(left[i], right[j], out=target)
                if sign < 0:
                    np.negative(target, out=target)
                continue
            np.multiply(left[i], right[j], out=row)
            if sign > 0:
                target += row
            else:
                target -= row


def log_into(quaternions, out, workspace):
    """`out = Log(q)` (3, K), the same for `q` and `-q`; leaves the angle `t`,
    `sin(t/2)`, `cos(t/2) = |w|` and `t / sin(t/2)` (0 for the identity) in the
    workspace's `angle`, `sine`, `cosine` and `ratio`."""
    ws = workspace
    vector = quaternions[1:]
    np.einsum("ik,ik->k", vector, vector, out=ws.sine)
    np.sqrt(ws.sine, out=ws.sine)
    np.abs(quaternions[0], out=ws.cosine)
    np.arctan2(ws.sine, ws.cosine, out=ws.angle)
    ws.angle *= 2.0
    # t / sin(t/2): accurate down to the smallest sines (atan2 is); adding SMALLEST changes
    # no sine above 1e-284, and gives 0 for the identity, whose vector part is 0 anyway.
    np.add(ws.sine, SMALLEST, out=ws.ratio)
    np.divide(ws.angle, ws.ratio, out=ws.ratio)
    if ws.cosine.all():
        # The hemisphere w > 0: the ratio takes the sign of w.
        np.copysign(ws.ratio, quaternions[0], out=ws.coefficient)
    else:
        # Some w = 0 exactly (180 degrees): the first nonzero of x, y, z decides.
        hemisphere_signs_into(quaternions[0], vector, ws.row)
        np.multiply(ws.ratio, ws.row, out=ws.coefficient)
    np.multiply(vector, ws.coefficient, out=out)


def hemisphere_signs_into(w, vector, out):
    """`quaternion.hemisphere_signs` in place into `out` (K,), from the scalar parts `w`
    (K,) and the vector parts `vector` (3, K): the sign of `w`, or for `w = 0` exactly that
    of the first nonzero of x, y, z."""
    np.sign(w, out=out)
    for component in vector:
        np.copyto(out, np.sign(component), where=out == 0.0)
    return out


def exp_into(rotation_vectors, out, workspace):
    """`out = Exp(r)` (4, K); leaves `t = |r|` in `angle`, `sin(t/2)` in `sine`, its `cos`
    in `cosine` and `sin(t/2) / t` (0 at 0) in `coefficient`.

    With `u = tan(t/4)`: `cos(t/2) = 2/(1 + u^2) - 1` and `sin(t/2) = u (1 + cos(t/2))`,
    one `tan` for both (`t` stays below `2 pi`: `e` is a log map's, `|e| <= pi`, moved by one
    step)."""
    ws = workspace
    np.einsum("ik,ik->k", rotation_vectors, rotation_vectors, out=ws.angle)
    np.sqrt(ws.angle, out=ws.angle)
    np.multiply(ws.angle, 0.25, out=ws.row)
    np.tan(ws.row, out=ws.row)
    np.multiply(ws.row, ws.row, out=ws.cosine)
    ws.cosine += 1.0
    np.divide(2.0, ws.cosine, out=ws.cosine)
    np.multiply(ws.row, ws.cosine, out=ws.sine)  # u (1 + cos) = u 2 / (1 + u^2)
    ws.cosine -= 1.0
    out[0] = ws.cosine
    np.add(ws.angle, SMALLEST, out=ws.row)
    np.divide(ws.sine, ws.row, out=ws.coefficient)
    np.multiply(rotation_vectors, ws.coefficient, out=out[1:])


def cross_into(first, second, out, row):
    """`out = first x second` for `(3, K)` arrays, `second` may be `(3, 1)` (`out` neither
    of them)."""
    for index in range(3):
        a, b = (index + 1) % 3, (index + 2) % 3
        np.multiply(first[a], second[b], out=out[index])
        np.multiply(first[b], second[a], out=row)
        out[index] -= row


def inverse_jacobian_into(rotation_vectors, vectors, out, workspace):
    """`out = J(r)^-1 v` (3, K), `v` (3, K) or (3, 1), with `angle`, `cosine` and `ratio` of
    `r` from `log_into` (no trigonometry):
    `J^-1 v = p v - r x v / 2 + c (r.v) r`, `p = (t/2) cot(t/2) = (t / sin(t/2)) |w| / 2`,
    `c = (1 - p) / t^2`, or near 0 `c = 1/12 + t^2/720 + t^4/30240` and `p = 1 - c t^2`."""
    ws = workspace
    p, c = ws.first, ws.second
    np.multiply(ws.ratio, ws.cosine, out=p)
    p *= 0.5
    _dot_scale_into(p, c, (1.0 / 30240.0, 1.0 / 720.0, 1.0 / 12.0), ws)
    _jacobian_terms_into(rotation_vectors, vectors, p, -0.5, c, out, ws)


def jacobian_into(rotation_vectors, vectors, out, workspace):
    """`out = J(r) v` (3, K), `v` (3, K) or (3, 1), with `angle`, `cosine` and
    `coefficient` of `r` from `exp_into`: `J v = p v + a r x v + b (r.v) r` with
    `p = sin t / t = 2 cos(t/2) sin(t/2)/t`, `a = (1 - cos t)/t^2 = 2 (sin(t/2)/t)^2`,
    `b = (1 - p) / t^2`, or near 0 `b = 1/6 - t^2/120 + t^4/5040` and `p = 1 - b t^2`."""
    ws = workspace
    p, a, b = ws.first, ws.ratio, ws.second
    np.multiply(ws.coefficient, ws.cosine, out=p)
    p *= 2.0
    np.multiply(ws.coefficient, ws.coefficient, out=a)
    a *= 2.0
    # At t = 0, `coefficient` is 0 rather than 1/2, and so is `a`; r x v is 0 there.
    _dot_scale_into(p, b, (1.0 / 5040.0, -(1.0 / 120.0), 1.0 / 6.0), ws)
    _jacobian_terms_into(rotation_vectors, vectors, p, a, b, out, ws)


def _dot_scale_into(p, scale, series_terms, workspace):
    """The Jacobians' `(r.v) r` factor `(1 - p) / t^2` (K,) into `scale`; where `t` is
    below `SERIES_BELOW`, the series `c4 t^4 + c2 t^2 + c0` of `series_terms`
    `(c4, c2, c0)` instead, and `p = 1 - scale t^2` there."""
    ws = workspace
    square = ws.row
    np.multiply(ws.angle, ws.angle, out=square)
    np.subtract(1.0, p, out=scale)
    np.add(square, SMALLEST, out=ws.dot)
    scale /= ws.dot
    np.less(ws.angle, SERIES_BELOW, out=ws.small)
    if ws.small.any():
        fourth, second, constant = series_terms
        series = ws.dot
        np.multiply(square, fourth, out=series)
        series += second
        series *= square
        series += constant
        np.copyto(scale, series, where=ws.small)
        series *= square
        np.subtract(1.0, series, out=series)
        np.copyto(p, series, where=ws.small)


def _jacobian_terms_into(rotation_vectors, vectors, p, cross_scale, dot_scale, out,
                         workspace):
    """`out = p v + s (r x v) + d (r.v) r` with `p` and `d` (K,) and `s` a number or (K,);
    `d` is overwritten."""
    ws = workspace
    if vectors.shape[1] == 1:
        # One v for all goals: `r x v` (rows 0-2) and `r.v` (row 3) are one product.
        x, y, z = vectors[:, 0]
        matrix = np.array([[0.0, z, -y], [-z, 0.0, x], [y, -x, 0.0], [x, y, z]])
        if np.isscalar(cross_scale):
            matrix[:3] *= cross_scale
        np.dot(matrix, rotation_vectors, out=ws.cross_dot)
        cross, dot = ws.cross_dot[:3], ws.cross_dot[3]
    else:
        cross_into(rotation_vectors, vectors, ws.cross, ws.dot)
        cross, dot = ws.cross, ws.dot
        np.einsum("ik,ik->k", rotation_vectors, vectors, out=dot)
        if np.isscalar(cross_scale):
            cross *= cross_scale
    if not np.isscalar(cross_scale):
        cross *= cross_scale
    np.multiply(vectors, p, out=out)
    out += cross
    dot *= dot_scale
    np.multiply(rotation_vectors, dot, out=ws.work)
    out += ws.work


def jacobian_of_one_values(rotation_vector, vector):
    """`J(r) v` for ONE rotation vector and vector, plain floats (two sequences of 3 in, a
    list of 3 out): at one column a NumPy call costs more than the whole product. The same
    formulas as `jacobian_into`, with `sin` and `cos` of `t` directly."""
    rx, ry, rz = rotation_vector
    vx, vy, vz = vector
    square = rx * rx + ry * ry + rz * rz
    angle = math.sqrt(square)
    if angle < SERIES_BELOW:
        b = 1.0 / 6.0 - square / 120.0 + square * square / 5040.0
        a = 0.5 - square / 24.0 + square * square / 720.0
        p = 1.0 - b * square
    else:
        half = 0.5 * angle
        a = 2.0 * (math.sin(half) / angle) ** 2
        p = math.sin(angle) / angle
        b = (1.0 - p) / square
    cx, cy, cz = ry * vz - rz * vy, rz * vx - rx * vz, rx * vy - ry * vx
    dot = b * (rx * vx + ry * vy + rz * vz)
    return [p * vx + a * cx + dot * rx, p * vy + a * cy + dot * ry, p * vz + a * cz + dot * rz]
