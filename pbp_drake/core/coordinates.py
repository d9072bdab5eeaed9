"""The numbers and positions the toolbox accepts: a real number is an int or a float (NumPy's
too), never a bool; a position is finite, and within `MAX_COORDINATE` metres of the origin
on every axis.

The bound is far beyond any scene a robot works in, so it refuses only data errors (a wrong
unit, a corrupted value): past about 1e154 a squared distance overflows to infinity, which
the whole-body QP and the differential IK would meet at every tick. Refused here, the run
stops with one message naming the position.
"""

import math

import numpy as np

MAX_COORDINATE = 1e6  # metres


def is_real(value):
    """Whether `value` is a real number: an int or a float, NumPy's too, but not a bool."""
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(
        value, bool)


def is_whole(value, least=0):
    """Whether `value` is a whole number (`is_real`, finite, with no fraction) >= `least`."""
    return is_real(value) and math.isfinite(value) and value >= least and int(value) == value


def vector_length(vector):
    """`np.linalg.norm` of a 1-D float vector as a float: the same number, which numpy
    computes as the square root of the vector's dot product with itself, without its
    dispatch (a few microseconds, called several times a control tick)."""
    vector = np.asarray(vector, dtype=float)
    return math.sqrt(vector.dot(vector))


def check_positions(positions, name):
    """Raises ValueError naming the first row of `positions` `(K, D)` (or one point `(D,)`)
    that is not finite or not within ±`MAX_COORDINATE` m, as `name` `k`."""
    positions = np.asarray(positions, dtype=float)
    # Two reductions, no temporary array, when all are good: a NaN fails both comparisons.
    if positions.size == 0 or (positions.min() >= -MAX_COORDINATE
                               and positions.max() <= MAX_COORDINATE):
        return
    rows = np.atleast_2d(positions)
    bad = ~(np.isfinite(rows) & (np.abs(rows) <= MAX_COORDINATE)).all(axis=1)
    index = int(np.flatnonzero(bad)[0])
    label = name if positions.ndim < 2 else f"{name} {index}"
    raise ValueError(f"{label} is {rows[index].tolist()}: positions must be finite and "
                     f"within ±{MAX_COORDINATE:g} m on every axis")
