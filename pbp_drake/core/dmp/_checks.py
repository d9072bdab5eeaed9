"""Input checks shared by the DMP modules: each names the field it refuses, as every input
check of the package does."""

import numpy as np

from pbp_drake.core.coordinates import is_real, is_whole
from pbp_drake.core.dmp.settings import DmpSettings


def read_only(array, dtype=None):
    """A private read-only C-order copy of `array`: a bank's model must not change under
    its users (threads, Drake Contexts), nor may it change an array its caller still holds."""
    array = np.array(array, dtype=dtype, order="C")
    array.setflags(write=False)
    return array


def as_point(value, name, dimension=None):
    """`value` as a new finite float vector `(D,)`; refuses empty, wrong-sized or NaN input."""
    point = np.array(value, dtype=float).reshape(-1)
    if point.size == 0:
        raise ValueError(f"{name} is empty")
    if dimension is not None and point.size != dimension:
        raise ValueError(f"{name} has {point.size} numbers, expected {dimension}")
    if not np.isfinite(point).all():
        raise ValueError(f"{name} contains NaN or infinite values: {point}")
    return point


def positive(value, name):
    """`value` as a float, refused unless finite and positive."""
    if not (is_real(value) and np.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be positive and finite, got {value}")
    return float(value)


def dmp_settings(settings):
    """`settings`, refused unless a `DmpSettings`."""
    if not isinstance(settings, DmpSettings):
        raise ValueError(f"settings must be DmpSettings, got {type(settings).__name__}")
    return settings


def goal_count_of(goal_count):
    """`goal_count` as an int, refused unless a whole number >= 1."""
    if is_real(goal_count) and goal_count < 1:
        raise ValueError("a DMP bank needs at least one goal")
    if not is_whole(goal_count, 1):
        raise ValueError(f"goal_count must be an integer >= 1, got {goal_count!r}")
    return int(goal_count)


def goal_indices(indices, goal_count):
    """`indices` as a flat integer array, refused unless one or more of `goal_count` goals'
    indices (0 to K - 1)."""
    indices = np.asarray(indices).reshape(-1)
    if (indices.size == 0 or not np.issubdtype(indices.dtype, np.integer)
            or indices.min() < 0 or indices.max() >= goal_count):
        raise ValueError(f"indices must be one or more of the bank's goal indices 0 to "
                         f"{goal_count - 1}, got {indices.tolist()}")
    return indices


def followed_velocity(velocity, followed, goal_count):
    """`velocity` (D, K), or with `followed` a goal index, that goal's column for every goal
    (PBP's goal switch: every DMP steps from the velocity the robot followed)."""
    if followed is None:
        return velocity
    if not 0 <= int(followed) < goal_count:
        raise ValueError(f"followed {followed} is not one of the {goal_count} goals")
    return np.repeat(velocity[:, [int(followed)]], goal_count, axis=1)


def broadcast_goalwise(values, goal_count, dimension, name):
    """Per-goal rows `(K, D)` (or one row `(D,)` for all goals) as a new `(D, K)` array."""
    values = np.asarray(values, dtype=float)
    if values.ndim == 1:
        values = np.broadcast_to(values, (goal_count, values.size))
    if values.shape != (goal_count, dimension):
        raise ValueError(f"{name} must be ({goal_count}, {dimension}) or ({dimension},)")
    if not np.isfinite(values).all():
        raise ValueError(f"{name} contains NaN or infinite values")
    return np.array(values.T, order="C")
