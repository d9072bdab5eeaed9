"""The hand-over law: how the command passes between the operator and the primitives
(why and its limits: docs/concepts/hand-over.md). With `(p_k, v_k)` the blended reference
of tick k and `v'_{k-1}` the velocity commanded at tick k - 1, the command of tick k is

    v'_k = v'_{k-1} + clip(cap(v_k) - v'_{k-1}, a_max dt)
    p'_k = p_k + (v'_k - v_k) dt

with `clip(d, r) = d min(1, r / |d|)` and `cap(v) = clip(v, v_max)`: the velocity changes
by at most `a_max dt` per control period and never exceeds `v_max`."""

import math

import numpy as np

from pbp_drake.core.coordinates import is_real, vector_length


def check_limit(value, name, unit):
    """`value` as a float; raises ValueError naming `name` unless it is a finite positive
    number."""
    if not is_real(value):
        raise ValueError(f"{name} must be a number ({unit}), got {value!r}")
    value = float(value)
    if not (math.isfinite(value) and value > 0.0):
        raise ValueError(f"{name} must be finite and positive ({unit}), got {value}")
    return value


def _clip(vector, largest):
    """`vector` scaled down to length `largest` when it is longer (a new array)."""
    size = vector_length(vector)
    return vector * (largest / size) if size > largest else np.array(vector, dtype=float)


def limited_velocity(previous_velocity, velocity, max_change, max_speed):
    """`v' = v'_prev + clip(cap(v) - v'_prev, max_change)`: the velocity law of the module
    docstring (`max_change = a_max dt`), a new array. The 6-DoF hand-over applies it to the
    angular velocity too (`pbp_drake.core.pose_arbitration`)."""
    previous_velocity = np.asarray(previous_velocity, dtype=float)
    velocity = np.asarray(velocity, dtype=float)
    return previous_velocity + _clip(_clip(velocity, max_speed) - previous_velocity, max_change)


def hand_over(previous_velocity, position, velocity, max_acceleration, max_speed, dt):
    """The command `(position, velocity)` of one tick under the hand-over law (module
    docstring), from the velocity commanded at the tick before and the blended reference
    `(position, velocity)`. New arrays; the inputs are left alone."""
    velocity = np.asarray(velocity, dtype=float)
    commanded = limited_velocity(previous_velocity, velocity, max_acceleration * dt, max_speed)
    return np.asarray(position, dtype=float) + (commanded - velocity) * dt, commanded
