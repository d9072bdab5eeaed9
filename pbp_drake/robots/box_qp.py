"""A box-constrained convex QP solved exactly, for the few variables of a robot's joints:
the whole-body diff IK's (`pbp_drake.robots.hsr_diff_ik`) at each of its steps."""

import math

import numpy as np
from numpy.linalg import _umath_linalg

_IDENTITIES = {}


def _solve_linear(a, b):
    """``np.linalg.solve(a, b)`` for a square ``a`` and a vector ``b``, the same LAPACK
    call (numpy's gufunc) without the wrapper's checks and error-state context, which cost
    more than the solve itself at a robot's size and run a few times every diff IK step. A
    singular ``a`` gives non-finite entries instead of LinAlgError: the caller checks."""
    return _umath_linalg.solve1(a, b, signature="dd->d")


def solve_box_qp(H, g, lower, upper, hold=None, max_iterations=100):
    """``argmin 0.5 x'Hx - g'x`` subject to ``lower <= x <= upper`` (H positive definite,
    ``lower <= upper``), exactly, quick for the few variables of a robot's joints.

    ``hold`` guesses which variables end at a bound (-1 lower, 1 upper, 0 neither), such
    as the last solution's. Returns the minimizer and which variables it holds at a bound.

    A primal-dual active-set method: each iteration solves with the variables held where
    the last one put them, then holds every free variable found out of its bounds and lets
    go every held one whose bound the cost pulls away from, all at once. It stops when
    nothing changes, which is `solve_box_qp_primal`'s own test of the minimum, with the
    system `solve_box_qp_primal` solves for that set of held variables: the same numbers,
    bit for bit. Such a method can cycle: after ``2 n + 2`` iterations it hands over to
    `solve_box_qp_primal`, which always ends.
    """
    n = g.size
    identity = _identity(n)
    guess = [0.0] * n if hold is None else np.asarray(hold).tolist()
    lows, highs, gs = lower.tolist(), upper.tolist(), g.tolist()
    tolerance = 1e-12 * (1.0 + max(map(abs, gs)))
    # -1 held at the lower bound, 1 at the upper, 0 free; a fixed variable is held.
    sides = [-1 if lows[i] == highs[i] or guess[i] < 0 else 1 if guess[i] > 0 else 0
             for i in range(n)]
    system, rhs = H.copy(), g.copy()
    for i in range(n):
        if sides[i]:
            system[i] = identity[i]
            rhs[i] = lows[i] if sides[i] < 0 else highs[i]
    for _ in range(2 * n + 2):
        target = _solve_linear(system, rhs)
        values = target.tolist()
        slopes = (H @ target - g).tolist()
        changed = False
        for i in range(n):
            side = sides[i]
            if side == 0 and (values[i] < lows[i] or values[i] > highs[i]):
                sides[i] = -1 if values[i] < lows[i] else 1
                system[i] = identity[i]
                rhs[i] = lows[i] if sides[i] < 0 else highs[i]
                changed = True
            elif side and lows[i] < highs[i] and ((side < 0 and slopes[i] < -tolerance)
                                                  or (side > 0 and slopes[i] > tolerance)):
                sides[i] = 0
                system[i] = H[i]
                rhs[i] = gs[i]
                changed = True
        if not changed:
            if not all(map(math.isfinite, values)):
                break  # a singular system: the primal method raises
            for i in range(n):
                if sides[i]:  # exactly at the bound, as the primal method sets them
                    target[i] = lows[i] if sides[i] < 0 else highs[i]
            return target, np.array(sides, dtype=float)
    return solve_box_qp_primal(H, g, lower, upper, hold, max_iterations)


def _identity(n):
    """The identity of size n, made once (np.eye costs as much as a solve here)."""
    if n not in _IDENTITIES:
        _IDENTITIES[n] = np.eye(n)
    return _IDENTITIES[n]


def solve_box_qp_primal(H, g, lower, upper, hold=None, max_iterations=100):
    """`solve_box_qp` by a primal active-set method, which always ends: from a feasible
    point it moves toward the minimum over the free variables as far as the first bound
    in the way, holding one variable at a time, and lets go of held ones whose bound the
    cost pulls away from.

    ``hold`` and the result as `solve_box_qp`'s; any guess gives the same minimum. The
    tests are made on Python lists (a numpy call per test costs more than the test), and
    the system solved is kept between iterations, a row changed where a variable is held or
    let go.
    """
    n = g.size
    identity = _identity(n)
    hold = np.zeros(n) if hold is None else np.asarray(hold)
    fixed = (hold != 0) | (lower == upper)
    x = np.clip(np.where(hold < 0, lower, np.where(hold > 0, upper, 0.0)), lower, upper)
    gs = g.tolist()
    tolerance = 1e-12 * (1.0 + max(map(abs, gs)))
    lows, highs = lower.tolist(), upper.tolist()
    held = fixed.tolist()
    system = np.where(fixed[:, None], identity, H)
    rhs = g.copy()
    for iteration in range(max_iterations):
        # The minimum over the free variables, the held ones where they are: the system's
        # rows and right side are H's and g's for a free variable (restored when it is let
        # go), the identity's and x's for a held one.
        np.copyto(rhs, x, where=fixed)
        target = _solve_linear(system, rhs)
        np.copyto(target, x, where=fixed)
        values = target.tolist()
        # The held variables sit exactly at a bound (set there by clip or assignment), so
        # only a free one can be found out of its bounds.
        outside = [i for i in range(n) if values[i] < lows[i] or values[i] > highs[i]]
        if outside:
            if iteration == 0:
                # The guess left these out of their bounds: hold them at the bounds
                # they passed, and go on from there (a feasible point).
                x = np.clip(target, lower, upper)
                for i in outside:
                    held[i] = fixed[i] = True
                    system[i] = identity[i]
                continue
            # Go as far toward the minimum as the first bound in the way (the first of
            # the smallest ratios, as np.argmin), and hold that variable there.
            step = target - x
            start = x.tolist()
            blocking, ratio = -1, 0.0
            for i in outside:
                bound = lows[i] if values[i] < lows[i] else highs[i]
                candidate = (bound - start[i]) / (values[i] - start[i])
                if blocking < 0 or candidate < ratio:
                    blocking, ratio, blocking_bound = i, candidate, bound
            x = np.clip(x + ratio * step, lower, upper)
            x[blocking] = blocking_bound
            held[blocking] = fixed[blocking] = True
            system[blocking] = identity[blocking]
            continue
        x = target
        # Held variables whose bound the cost pulls away from are let go: all at once,
        # or the one pulled hardest once that has taken long (which always ends).
        gradient = H @ x - g
        slopes = gradient.tolist()
        leaving = [i for i in range(n) if held[i] and lows[i] < highs[i] and (
            (values[i] <= lows[i] and slopes[i] < -tolerance)
            or (values[i] >= highs[i] and slopes[i] > tolerance))]
        if not leaving:
            if not all(map(math.isfinite, values)):  # a singular system: raise as numpy does
                np.linalg.solve(np.where(fixed[:, None], identity, H), np.where(fixed, x, g))
                raise np.linalg.LinAlgError("solve_box_qp met a singular system")
            return x, np.array([(-1.0 if values[i] <= lows[i] else
                                 1.0 if values[i] >= highs[i] else 0.0) if held[i] else 0.0
                                for i in range(n)])
        if iteration >= 2 * n:
            pulled = np.zeros(n, bool)
            pulled[leaving] = True
            leaving = [int(np.argmax(np.abs(gradient) * pulled))]
        for i in leaving:
            held[i] = fixed[i] = False
            system[i] = H[i]
            rhs[i] = gs[i]
    raise RuntimeError(f"solve_box_qp did not converge in {max_iterations} iterations")
