"""The orientation bank's step in log coordinates from ONE measured orientation `q` (4, 1)
and ONE scaled angular velocity `eta` (3, 1) for all K DMPs (PBP's goal switch, the six-DoF
Drake system's every tick), fused into two small BLAS products around one chain of
per-goal numbers: `A g` (`error_matrix`) is `q g*` and `v.eta`; `h = atan(s / w)`,
`k = h / s` give `e = 2 k v` and `p = k w`; then, with `d = 4 c k (v.eta)`,
`[e'; z'] = M [k v; d; c (e.eta) e; p; forcing rows]` (`combination_matrix`; the
attractor's part `b` in the rows of `forcing_rows`). The derivation and why it is faster:
docs/concepts/dmp.md, "Orientation DMPs". The results equal the general kernels'
(`orientation_kernels`) to rounding (`tests/core/test_orientation_bank_equivalence.py`); a
180-degree error (`w = 0`) takes `atan2` and the sign rule of `quaternion.canonical`."""

import functools

import numpy as np

from pbp_drake.core.dmp.orientation_kernels import (
    SMALLEST, conjugate_product_rows, hemisphere_signs_into)
from pbp_drake.core.quaternion import SERIES_BELOW

# The squared half angle below which `c` and `p` come from their series (the angle below
# `SERIES_BELOW`).
_SQUARE_SERIES_BELOW = (0.5 * SERIES_BELOW) ** 2
# The forcing rows' columns when they are `b` itself, six rows.
IDENTITY6 = tuple(tuple(float(row == column) for column in range(6)) for row in range(6))


def error_matrix(orientation, eta):
    """`A` (5, 4): `A g` is `q g*` (rows 0-3, `w` then `v`) and `v.eta` (row 4), for the
    measured orientation `(4, 1)` and velocity `(3, 1)`."""
    w, x, y, z = orientation[:, 0].tolist()
    a, b, c = eta[:, 0].tolist()
    return np.array(conjugate_product_rows(orientation) + [
        [a * x + b * y + c * z, -a * w - b * z + c * y, a * z - b * w - c * x,
         -a * y + b * x - c * w]])


def forcing_rows(shapes, lam, ijspeert, workspace):
    """Writes the attractor's part `b` (module docstring) into `fused`'s rows from 9 and
    returns the `(6, n)` columns of `M` that add it (rows of numbers, as
    `combination_matrix` builds `M` in one call): Ijspeert `b = S (-e0)`, Pastor
    `b = S + lambda e0`, from `shapes` `S` (2, 3, 1) or (2, 3, K) (which may be the
    workspace's `shape`, rows 9-14) and `lam` (2, 1) or (2, K); the workspace's `amplitude`
    and `start_errors` must be the goals'."""
    ws = workspace
    if ijspeert and shapes.shape[2] == 1:
        # One shape for all (shared weights, equal phases): `b_r = diag(S_r) (-e0)`, three
        # rows instead of six.
        np.copyto(ws.fused[9:12], ws.amplitude)
        return [[value if row == column else 0.0 for column in range(3)]
                for values in shapes[:, :, 0].tolist() for row, value in enumerate(values)]
    forcing = ws.shape
    if ijspeert:
        np.multiply(shapes, ws.amplitude, out=forcing)
    else:
        if not np.may_share_memory(shapes, ws.fused):  # else they are `shape` already
            np.copyto(forcing, shapes)
        np.multiply(ws.start_errors, lam[:, np.newaxis, :], out=ws.log_state)
        forcing += ws.log_state
    return IDENTITY6


def combination_matrix(transition, eta, forcing):
    """`M` (6, 8 + n) with `[e'; z'] = M [k v; d; c (e.eta) e; p; forcing rows]` (module
    docstring; `d`, a scratch row, gets a zero column), from `Phi` ((2, 2) numbers), the
    velocity `(3, 1)` and the forcing rows' columns (6 rows of n numbers): row block `i` of
    the first eight columns is `[2 Phi_i0 I + Phi_i1 [eta]x, 0, Phi_i1 I, Phi_i1 eta]`
    (`e = 2 k v`, and `-(e x eta)/2 = [eta]x e / 2`)."""
    a, b, c = eta[:, 0].tolist()
    rows = []
    for offset, s in transition:
        twice = 2.0 * offset
        rows += [[twice, -s * c, s * b, 0.0, s, 0.0, 0.0, s * a],
                 [s * c, twice, -s * a, 0.0, 0.0, s, 0.0, s * b],
                 [-s * b, s * a, twice, 0.0, 0.0, 0.0, s, s * c]]
    return np.array([row + list(extra) for row, extra in zip(rows, forcing)])


def log_step_from_one_into(orientation, eta, goals, transition, forcing, out, workspace):
    """`out` (2, 3, K) `= [e'; z']` of every goal, for one measured orientation `(4, 1)`
    (unit) and one `eta` (3, 1); `goals` (4, K), `transition` `Phi` ((2, 2) numbers), and
    `forcing` the columns of the attractor's rows (`forcing_rows`, called first), or None
    when `out` holds `b` already (the product is then added to it). Writes the
    workspace's `fused` and `small`, `fused`'s rows rewritten in place as soon as their
    values are dead (the step's cost at large K is the memory it touches); allocates
    nothing of size K."""
    ws = workspace
    fused = ws.fused
    np.matmul(error_matrix(orientation, eta), goals, out=fused[:5])
    w, vector, along = fused[0], fused[1:4], fused[4]
    # The per-goal numbers live in the rows `c (e.eta) e` and `p` take last: no more memory.
    ratio, half, quadruple, p = fused[5], fused[6], fused[7], fused[8]
    np.einsum("ik,ik->k", vector, vector, out=ratio)
    np.sqrt(ratio, out=ratio)  # s = |v| = sin(t/2)
    if np.logical_and.reduce(w):  # no w = 0 (`w.all()`, without its Python wrapper)
        # h = atan(s / w) = sign(w) t/2 (|w| = cos(t/2)): `-q g*`'s angle with `q g*`'s
        # sign, so that `h / s` is `k` and `h w / s` is `p` with no sign pass. One rounding
        # of the quotient away from `atan2`, and 3.5 times faster.
        np.divide(ratio, w, out=half)
        np.arctan(half, out=half)
    else:
        # Some w = 0 exactly (180 degrees): the first nonzero of x, y, z decides the sign,
        # as `quaternion.canonical`.
        hemisphere_signs_into(w, vector, ws.row)
        np.abs(w, out=half)
        np.arctan2(ratio, half, out=half)
        half *= ws.row
    # h^2, in the row `4 c` takes last: one pass tells whether any angle needs the series.
    square = quadruple
    np.multiply(half, half, out=square)
    if np.minimum.reduce(square) >= _SQUARE_SERIES_BELOW:  # False if NaN: the general path
        # Every angle at least SERIES_BELOW: then `s >= |h w|` (atan x <= x) or `|w| < 0.1`
        # and `s > 0.99`, so `s` and `h^2` are above 1e-5, where adding SMALLEST (as the
        # general path does) changes no bit: left out, with the series' mask and its test.
        np.divide(half, ratio, out=ratio)  # k = h / s
        np.multiply(ratio, w, out=p)  # p = (t/2) cot(t/2) = h w / s
        vector *= ratio  # k v = e / 2
        np.subtract(1.0, p, out=half)
        np.divide(half, square, out=quadruple)  # 4 c = (1 - p) / h^2
    else:
        quadruple = _small_angles_into(w, vector, ratio, half, square, p, ws.small)
    # d = (4 c)(k v.eta), and c (e.eta) e = d (k v) (over k, h and 4 c, dead by then).
    along *= ratio
    along *= quadruple
    np.multiply(vector, along, out=fused[5:8])
    if forcing is None:
        # `out` holds `b`: BLAS adds the product to it (beta = 1), as fast as the product
        # alone and a third faster than taking `b`'s six rows into it.
        _accumulate_product(combination_matrix(transition, eta, ((),) * 6), fused[1:9],
                            out.reshape(6, -1))
    else:
        np.matmul(combination_matrix(transition, eta, forcing), fused[1:9 + len(forcing[0])],
                  out=out.reshape(6, -1))


@functools.cache
def _dgemm():
    # SciPy's BLAS wrapper, imported on first use: `scipy.linalg` takes 0.2 s to import,
    # which only the six-DoF step should pay.
    from scipy.linalg.blas import dgemm
    return dgemm


def _accumulate_product(matrix, rows, out):
    """`out += matrix @ rows` in place, `out` (m, K) C-contiguous: BLAS's
    `C = A B + C` on the transposes (Fortran order, so no copy is made)."""
    result = _dgemm()(1.0, rows.T, matrix.T, beta=1.0, c=out.T, overwrite_c=True)
    if not np.may_share_memory(result, out):  # a copy would leave `out` as it was
        raise RuntimeError("BLAS dgemm did not write in place")


def _small_angles_into(w, vector, ratio, half, square, p, small):
    """`log_step_from_one_into`'s numbers when some angle may be below SERIES_BELOW (or
    is 0, the identity, whose `s` is 0): `k` into `ratio`, `p`, `k v` into `vector`, and
    `4 c` from the closed forms with SMALLEST in their denominators, then the series where
    the angle is small. `half` holds `h` and `square` `h^2` on entry; returns the row that
    holds `4 c` (`half`); `w` ends as scratch."""
    # k = h / s (0 for the identity, whose v is 0 anyway; SMALLEST changes no s > 1e-284).
    ratio += SMALLEST
    np.divide(half, ratio, out=ratio)
    np.multiply(ratio, w, out=p)  # p = (t/2) cot(t/2) = h w / s
    vector *= ratio  # k v = e / 2
    # 4 c = (1 - p) / h^2, or its series where the angle is below SERIES_BELOW.
    quadruple, scratch = half, w
    np.less(square, _SQUARE_SERIES_BELOW, out=small)
    np.subtract(1.0, p, out=quadruple)
    np.add(square, SMALLEST, out=scratch)
    quadruple /= scratch
    if small.any():
        _series_into(square, quadruple, p, scratch, small)
    return quadruple


def _series_into(square, quadruple, p, series, small):
    """Where `small`: `4 c` and `p = 1 - c t^2` from `c = 1/12 + t^2/720 + t^4/30240`,
    with `t^2 = 4 h^2` (`square` is `h^2`): the closed form loses digits there."""
    np.multiply(square, 4.0 / 30240.0, out=series)  # in t^2 = 4 h^2
    series += 1.0 / 720.0
    series *= square
    series *= 4.0
    series += 1.0 / 12.0
    series *= 4.0  # 4 c
    np.copyto(quadruple, series, where=small)
    series *= square  # 4 c h^2 = c t^2
    np.subtract(1.0, series, out=series)
    np.copyto(p, series, where=small)
