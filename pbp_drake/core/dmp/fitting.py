"""Demonstrations and learning: the minimum-jerk reach, input checks, and the one-demo fit.

The fit is locally weighted regression per basis function on ONE demonstration (Ijspeert
et al. 2013): `w_i = sum_t s_t psi_i(x_t) f_t / sum_t s_t^2 psi_i(x_t)`, written here in
attractor form (`tau dz = K (y_attr - y) - D z`, solved for `y_attr` along the demo).
"""

import numpy as np

from pbp_drake.core.coordinates import is_whole
from pbp_drake.core.dmp._checks import as_point, dmp_settings, positive
from pbp_drake.core.dmp.settings import DmpSettings


def minimum_jerk(start, goal, duration, sample_count=200):
    """Times `(T,)` and positions `(T, D)` of a minimum-jerk straight path, rest to rest."""
    start = as_point(start, "start")
    goal = as_point(goal, "goal", dimension=start.size)
    duration = positive(duration, "duration")
    if not is_whole(sample_count, 2):
        raise ValueError(f"sample_count must be a whole number >= 2, got {sample_count!r}")
    times = np.linspace(0.0, duration, int(sample_count))
    s = times / duration
    progress = 10 * s**3 - 15 * s**4 + 6 * s**5
    return times, start + np.outer(progress, goal - start)


def validate_demonstration(times, positions):
    """Checks a demonstration and returns it as float arrays `(T,)`, `(T, D)`."""
    positions = np.asarray(positions, dtype=float)
    if positions.ndim == 1:
        positions = positions[:, np.newaxis]
    if positions.ndim != 2:
        raise ValueError(f"demonstration positions must be (T, D), got shape {positions.shape}")
    if positions.shape[0] < 3:
        raise ValueError(
            f"demonstration has {positions.shape[0]} samples; at least 3 are needed"
        )
    bad = np.flatnonzero(~np.isfinite(positions).all(axis=1))
    if bad.size:
        raise ValueError(f"demonstration positions are NaN or infinite at sample {bad[0]}")
    return check_times(times, positions.shape[0]), positions


def check_times(times, count):
    """A demonstration's `times` as a float array `(count,)`, refused unless finite and
    strictly increasing."""
    times = np.asarray(times, dtype=float)
    if times.shape != (count,):
        raise ValueError(f"demonstration times have shape {times.shape}, expected ({count},)")
    if not np.isfinite(times).all() or not (np.diff(times) > 0).all():
        raise ValueError("demonstration times must be finite and strictly increasing")
    return times


def fit_weights(times, positions, settings=DmpSettings()):
    """Forcing-term weights `(N, D)` from ONE demonstration by locally weighted regression.

    Returns `(weights, amplitude_scaling)`; `amplitude_scaling[d]` is False where the
    Ijspeert `(g - y0)` factor was switched off because the demonstration's amplitude is over
    twice its start-to-goal distance (the reference code's guard, which also covers `g = y0`).
    """
    times, positions = validate_demonstration(times, positions)
    dmp_settings(settings)
    elapsed = times - times[0]
    tau = elapsed[-1]
    start, goal = positions[0], positions[-1]
    velocity = np.gradient(positions, elapsed, axis=0)
    acceleration = np.gradient(velocity, elapsed, axis=0)
    phase = np.exp(-settings.alpha_x * elapsed / tau)
    k, d = settings.stiffness, settings.damping
    # The attractor the demonstration implies: tau dz = K (y_attr - y) - D z, solved for y_attr.
    attractor = positions + (tau**2 * acceleration + d * tau * velocity) / k

    span = goal - start
    amplitude = positions.max(axis=0) - positions.min(axis=0)
    amplitude_scaling = amplitude <= 2.0 * np.abs(span)
    if settings.formulation == "ijspeert":
        scale = np.where(amplitude_scaling, span, 1.0)
        target = attractor - goal
        regressor = np.outer(phase, scale) / k
    else:
        target = attractor - goal + np.outer(phase, span)
        regressor = np.repeat(phase[:, np.newaxis], positions.shape[1], axis=1)
        amplitude_scaling = np.zeros_like(amplitude_scaling)

    centres, widths = settings.basis()
    psi = np.exp(-widths[:, np.newaxis] * (phase[np.newaxis, :] - centres[:, np.newaxis]) ** 2)
    numerator = psi @ (regressor * target)
    denominator = psi @ (regressor**2)
    weights = np.divide(
        numerator, denominator, out=np.zeros_like(numerator), where=denominator > 1e-300
    )
    return weights, amplitude_scaling
