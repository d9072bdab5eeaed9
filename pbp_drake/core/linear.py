"""Exact zero-order-hold discretisation of small linear systems.

Both the DMP transformation system and the point robot are linear between control ticks, so
stepping them with `expm(A dt)` is exact and costs no more than Euler. NumPy has no `expm` and
the core must not depend on SciPy or Drake, hence this small scaling-and-squaring version.
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


def second_order_transition(stiffness, damping, time_scale, dt):
    """Transition matrix of `time_scale * [y', z'] = [z, -stiffness*y - damping*z]` over `dt`.

    This is the DMP transformation system written around its moving attractor; the returned
    2x2 `Phi` maps `[y - y_attractor, z]` at `t` to the same at `t + dt`.
    """
    a = np.array([[0.0, 1.0], [-stiffness, -damping]]) / time_scale
    return expm(a * dt)
