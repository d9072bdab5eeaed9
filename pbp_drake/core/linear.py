"""Closed-form discretisation of small linear systems.

The point robot is linear between plant steps with its command held, so stepping it with
`expm(A dt)` is exact (zero-order hold) and costs no more than Euler. The DMP transformation
system is linear around its moving attractor; holding the attractor linear in time over a
step (first-order hold) adds one integral of `expm(A s)` (`second_order_step`). NumPy has no
`expm` and the core must not depend on SciPy or Drake, hence this small
scaling-and-squaring version.
"""

import numpy as np


def expm(matrix):
    """Matrix exponential of a small square matrix (scaling and squaring, Taylor order 20).

    Accurate to machine precision for the well-scaled 2x2 and 4x4 matrices used here.
    """
    a = np.asarray(matrix, dtype=float)
    if a.ndim != 2 or a.shape[0] != a.shape[1]:
        raise ValueError(f"expm needs a square matrix, got shape {a.shape}")
    norm = np.linalg.norm(a, ord=np.inf)
    squarings = max(0, int(np.ceil(np.log2(norm))) + 1) if norm > 0.5 else 0
    scaled = a / (2.0**squarings)
    result = np.eye(a.shape[0])
    term = np.eye(a.shape[0])
    for order in range(1, 21):
        term = term @ scaled / order
        result = result + term
    for _ in range(squarings):
        result = result @ result
    return result


def second_order_step(stiffness, damping, time_scale, dt):
    """`(Phi, Gamma)` of `time_scale * [y', z'] = [z, -stiffness*y - damping*z]` over `dt`:
    `Phi = expm(A dt)` and `Gamma = integral_0^dt expm(A s) ds`, both 2x2, from one
    exponential of the augmented matrix `[[A, I], [0, 0]] dt`.

    This is the DMP transformation system written around its moving attractor `a(t)`: with
    `w = [y - a, z]`, `w' = A w - [a', 0]`, so `w(dt) = Phi w(0) - Gamma [r, 0]` when `a`
    moves at the constant rate `r` over the step (and `Phi w(0)` when it stands still).
    """
    augmented = np.zeros((4, 4))
    augmented[:2, :2] = np.array([[0.0, 1.0], [-stiffness, -damping]]) / time_scale
    augmented[:2, 2:] = np.eye(2)
    exponential = expm(augmented * dt)
    return exponential[:2, :2], exponential[:2, 2:]

