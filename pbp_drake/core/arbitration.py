"""How the operator's command and the robot's policy become one reference (the blending laws).

Every law returns the reference the robot tracks next: a position and a velocity. The
operator's command `u` is a velocity; over one control period `dt` the operator alone would
move the robot from `y` to `U = y + u dt`.

- ``pbp_continuous`` (Alg. 1): the DMP's next state plus the operator's displacement,
  `T = y_dmp + u dt`. The DMP keeps running.
- ``pbp_alternated`` (Alg. 2): while the operator acts, the operator alone, `T = U`
  (the DMP bank locks its phase); otherwise the DMP, `T = y_dmp`.
- ``fixed_alpha`` (Dragan & Srinivasa 2013): `T = (1 - alpha) U + alpha P` while the
  operator acts, `T = P` otherwise (an idle operator has no command to blend; at alpha 0 the
  operator has full control when acting, at alpha 1 the operator is ignored).
- ``teleop``: `T = U`.
"""

import numpy as np

BLEND_MODES = ("pbp_continuous", "pbp_alternated", "fixed_alpha", "teleop")


def validate_mode(mode, alpha=None):
    if mode not in BLEND_MODES:
        raise ValueError(f"blending mode {mode!r} is unknown; choose one of {BLEND_MODES}")
    if mode == "fixed_alpha":
        if alpha is None or not np.isfinite(alpha) or not 0.0 <= alpha <= 1.0:
            raise ValueError(f"alpha must lie in [0, 1] for fixed_alpha, got {alpha}")


def validate_command(command, name="operator_command"):
    command = np.asarray(command, dtype=float)
    if not np.isfinite(command).all():
        raise ValueError(f"{name} is NaN or infinite: {command}")
    return command


def blend(mode, robot_position, policy_position, policy_velocity, command, active, dt,
          alpha=None):
    """The reference (position, velocity) to track for one control period.

    `policy_*` is the robot policy's next state (the selected DMP's, or the open-loop
    demonstration's for explicit arbitration); `command` the operator's velocity; `active`
    whether the operator acts this step.
    """
    command = validate_command(command)
    operator_position = robot_position + command * dt
    if mode == "pbp_continuous":
        return policy_position + command * dt, policy_velocity + command
    if mode == "teleop" or (mode == "pbp_alternated" and active):
        return operator_position, command
    if mode == "pbp_alternated" or not active:
        return policy_position, policy_velocity
    if mode == "fixed_alpha":
        return ((1.0 - alpha) * operator_position + alpha * policy_position,
                (1.0 - alpha) * command + alpha * policy_velocity)
    raise ValueError(f"blending mode {mode!r} is unknown; choose one of {BLEND_MODES}")
