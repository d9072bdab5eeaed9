"""Unit quaternions for orientations, vectorised: product, conjugate, log and exp maps,
slerp, the hemisphere choice, and the left Jacobian of SO(3).

Convention (the whole package keeps it): a quaternion is `(w, x, y, z)`, scalar first, with
Hamilton's product; `q` rotates a vector `p` as `q (0, p) q*`, so it maps body to world.
The functions take the quaternion on the FIRST axis, `(4, ...)` (and rotation vectors as
`(3, ...)`), so that a bank lays K orientations out `(4, K)` as the position bank lays out
`(D, K)`; one quaternion is `(4,)`. Users give quaternions as rows `(..., 4)`
(`unit_quaternions` checks them). Rotation vectors are angle times unit axis (the full
angle, twice the quaternion logarithm), and `log_map` gives `q` and `-q` the same one."""

import math

import numpy as np

# How far from 1 a quaternion's norm may be and still be taken as a unit quaternion (then
# divided by its norm): float32 data passes (1e-7), a vector that is not a quaternion does
# not.
UNIT_TOLERANCE = 1e-6
# Below this angle (radians) the Jacobian coefficients come from their Taylor series: the
# closed forms' relative error grows as eps / t^2 (1e-11 here), the series' next term is
# t^8 / 4e7 (below 1e-23).
SERIES_BELOW = 1e-2
IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])
IDENTITY.setflags(write=False)


def unit_quaternions(values, name):
    """Quaternion rows `(..., 4)` checked and divided by their norms, as a new float array.

    Raises ValueError naming `name` if the last axis is not 4 long, if a row is NaN or
    infinite, or if a norm is further than `UNIT_TOLERANCE` from 1."""
    rows = np.array(values, dtype=float)
    if rows.ndim == 0 or rows.shape[-1] != 4 or rows.size == 0:
        raise ValueError(f"{name} must be quaternions (w, x, y, z) of 4 numbers, got shape "
                         f"{rows.shape}")
    flat = rows.reshape(-1, 4)
    bad = np.flatnonzero(~np.isfinite(flat).all(axis=1))
    if bad.size:
        raise ValueError(f"{name} contains NaN or infinite values (quaternion {bad[0]}: "
                         f"{flat[bad[0]]})")
    norms = np.linalg.norm(flat, axis=1)
    off = np.flatnonzero(np.abs(norms - 1.0) > UNIT_TOLERANCE)
    if off.size:
        raise ValueError(f"{name} is not a unit quaternion (w, x, y, z): quaternion {off[0]} "
                         f"{flat[off[0]]} has norm {norms[off[0]]:.9g}; norms must be within "
                         f"{UNIT_TOLERANCE:g} of 1")
    flat /= norms[:, np.newaxis]
    return rows


def unit_norm(quaternion, name):
    """The norm of one quaternion (4,), checked as `unit_quaternions` checks it (ValueError
    naming `name` when it is further than `UNIT_TOLERANCE` from 1): a control tick's check,
    `unit_quaternions` costing 50 us a call."""
    norm = math.sqrt(float(quaternion @ quaternion))
    if abs(norm - 1.0) > UNIT_TOLERANCE:
        unit_quaternions(quaternion, name)  # raises, naming it
    return norm


def multiply(p, q):
    """Hamilton's product `p q` of quaternions `(4, ...)` (broadcast)."""
    pw, px, py, pz = p
    qw, qx, qy, qz = q
    return np.stack([pw * qw - px * qx - py * qy - pz * qz,
                     pw * qx + px * qw + py * qz - pz * qy,
                     pw * qy - px * qz + py * qw + pz * qx,
                     pw * qz + px * qy - py * qx + pz * qw])


def conjugate(q):
    """`q* = (w, -x, -y, -z)`: the inverse of a unit quaternion, a new array."""
    result = -np.asarray(q, dtype=float)
    result[0] = -result[0]
    return result


def hemisphere_signs(q):
    """`+1` or `-1` per quaternion `(4, ...)`: the sign that makes `w > 0`; for `w = 0`
    exactly, the first nonzero of `x, y, z` decides (so that `q` and `-q` get opposite
    signs, and hence the same canonical quaternion)."""
    signs = np.sign(q[0])
    for component in q[1:]:
        signs = np.where(signs == 0.0, np.sign(component), signs)
    return signs


def canonical(q):
    """`q` or `-q`, whichever is in the hemisphere `w >= 0` (see `hemisphere_signs`)."""
    return q * hemisphere_signs(q)


def aligned(q, reference):
    """`q` or `-q`, whichever is closer to `reference` (dot product >= 0): the sign that
    keeps a stream of quaternions continuous. Both `(4, ...)`, broadcast."""
    dots = np.sum(q * reference, axis=0)
    return np.where(dots < 0.0, -q, q)


def log_map(q):
    """Rotation vectors `(3, ...)` of unit quaternions `(4, ...)`: angle in [0, pi] times
    axis, the same for `q` and `-q`."""
    q = canonical(np.asarray(q, dtype=float))
    vector = q[1:]
    sine = np.sqrt(np.sum(vector * vector, axis=0))  # sin(angle / 2)
    angle = 2.0 * np.arctan2(sine, q[0])
    tiny = sine < 1e-8
    # angle / sin(angle / 2) -> 2 / w as the angle goes to 0 (w is then 1 to 1e-16).
    ratio = np.where(tiny, 2.0 / np.where(tiny, q[0], 1.0), angle / np.where(tiny, 1.0, sine))
    return vector * ratio


def exp_map(rotation_vector):
    """Unit quaternions `(4, ...)` (with `w >= 0` for angles up to pi) of rotation vectors
    `(3, ...)`: `(cos(|r|/2), sin(|r|/2) r/|r|)`."""
    rotation_vector = np.asarray(rotation_vector, dtype=float)
    angle = np.sqrt(np.sum(rotation_vector * rotation_vector, axis=0))
    # sin(angle / 2) / angle, exact at 0: numpy's sinc(u) = sin(pi u) / (pi u).
    half_sinc = 0.5 * np.sinc(angle / (2.0 * np.pi))
    return np.concatenate([np.cos(0.5 * angle)[np.newaxis], rotation_vector * half_sinc])


def exp_times_aligned_values(rotation_vector, q, reference):
    """`aligned(multiply(exp_map(r), q), reference)` for ONE rotation vector and quaternions
    `q`, `reference`, on plain floats (sequences of 3, 4 and 4 in, a list of 4 out): the
    same operations in the same order, so the same numbers bit for bit, at a tenth of the
    time (at one quaternion a NumPy call costs more than the whole product)."""
    rx, ry, rz = rotation_vector
    qw, qx, qy, qz = q
    angle = math.sqrt(rx * rx + ry * ry + rz * rz)
    # numpy's sinc(u) = sin(pi u) / (pi u), with u = 1e-20 at 0 (exp_map).
    u = angle / (2.0 * math.pi)
    y = math.pi * (u if u != 0.0 else 1.0e-20)
    half_sinc = 0.5 * (math.sin(y) / y)
    pw = math.cos(0.5 * angle)
    px, py, pz = rx * half_sinc, ry * half_sinc, rz * half_sinc
    product = [pw * qw - px * qx - py * qy - pz * qz,
               pw * qx + px * qw + py * qz - pz * qy,
               pw * qy - px * qz + py * qw + pz * qx,
               pw * qz + px * qy - py * qx + pz * qw]
    dot = sum(value * other for value, other in zip(product, reference))
    return [-value for value in product] if dot < 0.0 else product


def angle_between(p, q):
    """The rotation angle (radians, in [0, pi]) from `q` to `p`, the same for `-p` or `-q`."""
    return np.sqrt(np.sum(log_map(multiply(p, conjugate(q))) ** 2, axis=0))


def slerp(start, end, fraction):
    """Spherical linear interpolation along the shorter arc: `Exp(s Log(end start*)) start`.

    `start`, `end` `(4, ...)`, `fraction` broadcast against their trailing axes; a new
    `(4, ...)` array, on the hemisphere of `start`."""
    rotation = log_map(multiply(end, conjugate(start)))
    return aligned(multiply(exp_map(rotation * np.asarray(fraction, dtype=float)), start),
                   start)


def _jacobian_coefficients(angle):
    """`(a, b, c)` for angles `t` `(...)`, in `J(r) v = v + a r x v + b r x (r x v)` and
    `J(r)^-1 v = v - r x v / 2 + c r x (r x v)`: `a = (1 - cos t)/t^2`,
    `b = (t - sin t)/t^3`, `c = (1 - (t/2) cot(t/2)) / t^2`, `b` and `c` from short series
    below `SERIES_BELOW` radians, where the closed forms lose digits to cancellation."""
    small = angle < SERIES_BELOW
    safe = np.where(small, 1.0, angle)
    square = angle * angle
    # (1 - cos t)/t^2 = (sin(t/2) / (t/2))^2 / 2: no cancellation at any angle.
    a = 0.5 * np.sinc(angle / (2.0 * np.pi)) ** 2
    b = np.where(small, 1.0 / 6.0 - square / 120.0 + square**2 / 5040.0,
                 (safe - np.sin(safe)) / safe**3)
    half = 0.5 * safe
    c = np.where(small, 1.0 / 12.0 + square / 720.0 + square**2 / 30240.0,
                 (1.0 - half * np.cos(half) / np.sin(half)) / (safe * safe))
    return a, b, c


def left_jacobian_times(rotation_vector, vector):
    """`J(r) v` for rotation vectors `r` and vectors `v`, both `(3, ...)`: the world-frame
    angular velocity of `Exp(r)` when `r` changes at the rate `v` (J is the left Jacobian
    of SO(3), invertible for `|r| < 2 pi`)."""
    angle = np.sqrt(np.sum(rotation_vector * rotation_vector, axis=0))
    a, b, _ = _jacobian_coefficients(angle)
    cross = np.cross(rotation_vector, vector, axis=0)
    return vector + a * cross + b * np.cross(rotation_vector, cross, axis=0)


def left_jacobian_inverse_times(rotation_vector, vector):
    """`J(r)^-1 v`, for `|r| < 2 pi`: the rate of `r` at which `Exp(r)` turns at the
    world-frame angular velocity `v`."""
    angle = np.sqrt(np.sum(rotation_vector * rotation_vector, axis=0))
    _, _, c = _jacobian_coefficients(angle)
    cross = np.cross(rotation_vector, vector, axis=0)
    return vector - 0.5 * cross + c * np.cross(rotation_vector, cross, axis=0)
