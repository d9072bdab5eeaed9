"""How the operator's command and the robot's policy become one reference: the blending laws
(`BLEND_LAWS`; the table: docs/concepts/pbp.md, "The blending laws"). The operator's command
`u` is a velocity; over one control period `dt` the operator alone would move the robot from
`y` to `U = y + u dt`; `P` is the policy's next state (the selected DMP's). A law plays `U`,
`P`, `P + u dt` or `(1 - alpha) U + alpha P` while the operator acts and while idle;
``confidence_alpha`` takes alpha from the goal confidence (`confidence_alpha`)."""

import typing

import numpy as np

from pbp_drake.core.choices import unknown_choice
from pbp_drake.core.coordinates import is_real

#: `BlendLaw.weight` of a law whose weight alpha is the method's own (`scenario.alpha`) ...
FIXED_WEIGHT = "fixed"
#: ... and of one whose alpha is the goal confidence's ramp, every control period.
CONFIDENCE_WEIGHT = "confidence"

# Defaults of the confidence -> alpha ramp of ``confidence_alpha``.
DEFAULT_CONFIDENCE_LOW = 0.0
DEFAULT_CONFIDENCE_HIGH = 1.0
DEFAULT_ALPHA_MAX = 1.0

#: What a law plays (`BlendLaw.acting`, `BlendLaw.idle`): the module docstring's `U`, `P`,
#: `P + u dt` and `(1 - alpha) U + alpha P`.
OPERATOR = "operator"
POLICY = "policy"
SHIFTED = "shifted"
MIXED = "mixed"


class BlendLaw(typing.NamedTuple):
    """One blending law: what it plays while the operator acts and while idle (`OPERATOR`,
    `POLICY`, `SHIFTED` or `MIXED`); what its weight alpha is (`FIXED_WEIGHT`,
    `CONFIDENCE_WEIGHT` or None: no weight); and whether the operator's command adds to a
    policy that keeps running (the DMPs' speed is then capped)."""

    acting: str
    idle: str
    weight: typing.Optional[str] = None
    adds_to_policy: bool = False


#: The blending laws by mode name; a method names its law
#: (`pbp_drake.core.methods.Method.blend_mode`).
BLEND_LAWS = {
    "pbp_continuous": BlendLaw(SHIFTED, SHIFTED, adds_to_policy=True),
    "pbp_alternated": BlendLaw(OPERATOR, POLICY),
    "fixed_alpha": BlendLaw(MIXED, POLICY, FIXED_WEIGHT),
    "teleop": BlendLaw(OPERATOR, OPERATOR),
    "confidence_alpha": BlendLaw(MIXED, POLICY, CONFIDENCE_WEIGHT),
}
BLEND_MODES = tuple(BLEND_LAWS)


def blend_law(mode, laws=BLEND_LAWS):
    """The `BlendLaw` of `mode` in `laws`; ValueError naming the modes for an unknown one."""
    if mode not in laws:
        raise ValueError(unknown_choice("blending mode", mode, laws))
    return laws[mode]


def check_alpha(mode, alpha):
    """Raises ValueError unless `alpha` is a finite number in [0, 1]."""
    if not is_real(alpha) or not np.isfinite(alpha) or not 0.0 <= alpha <= 1.0:
        raise ValueError(f"alpha must lie in [0, 1] for {mode}, got {alpha}")


def validate_mode(mode, alpha=None, laws=BLEND_LAWS):
    """Raises ValueError for a mode unknown to `laws`, or a fixed-weight one without alpha in
    [0, 1]."""
    if blend_law(mode, laws).weight == FIXED_WEIGHT:
        check_alpha(mode, alpha)


def played_reference(mode, active, alpha, laws=BLEND_LAWS):
    """What `mode`'s law plays this control period (`BlendLaw.acting` or `BlendLaw.idle`);
    ValueError for a mode unknown to `laws`, or a weighted one acting without alpha in [0, 1]."""
    law = blend_law(mode, laws)
    if law.weight is not None and active:
        check_alpha(mode, alpha)
    return law.acting if active else law.idle


def validate_confidence_ramp(low, high, alpha_max):
    """Checks the ramp of ``confidence_alpha``: `0 <= low < high <= 1`, `0 < alpha_max <= 1`."""
    for name, value in (("confidence_low", low), ("confidence_high", high),
                        ("alpha_max", alpha_max)):
        if isinstance(value, bool) or not np.isscalar(value) or not np.isfinite(value):
            raise ValueError(f"{name} must be a finite number, got {value!r}")
    if not 0.0 <= low <= 1.0:
        raise ValueError(f"confidence_low must lie in [0, 1], got {low}")
    if not 0.0 <= high <= 1.0:
        raise ValueError(f"confidence_high must lie in [0, 1], got {high}")
    if not low < high:
        raise ValueError(f"confidence_low must be below confidence_high, got "
                         f"confidence_low={low}, confidence_high={high}")
    if not 0.0 < alpha_max <= 1.0:
        raise ValueError(f"alpha_max must lie in (0, 1], got {alpha_max}")


def goal_confidence(probabilities, selected):
    """The margin of the selected goal: `p[selected] - max_{j != selected} p[j]`, at least 0.

    `probabilities` (K >= 1, finite, non-negative, not all 0) are normalised to sum 1 first.
    Uniform gives 0, one-hot on `selected` gives 1, K = 1 gives 1. The Jain-style margin
    (Jain & Argall 2019) rather than the normalised maximum `(p_max - 1/K) / (1 - 1/K)`: it
    is 0 whenever the selected goal is tied with another (`[0.5, 0.5, 0]`), and it measures
    the *selected* goal, which the estimator's hysteresis may keep after another became more
    probable (the operator then keeps full control).
    """
    probabilities = np.asarray(probabilities, dtype=float).reshape(-1)
    k = probabilities.size
    if k == 0:
        raise ValueError("goal_probabilities is empty")
    if not np.isfinite(probabilities).all() or (probabilities < 0.0).any():
        raise ValueError(f"goal_probabilities must be finite and non-negative, got "
                         f"{probabilities}")
    total = probabilities.sum()
    if total <= 0.0:
        raise ValueError(f"goal_probabilities sum to {total}; they must sum to a positive "
                         f"number")
    if isinstance(selected, bool) or int(selected) != selected or not 0 <= selected < k:
        raise ValueError(f"selected goal {selected!r} is not one of the {k} goals")
    probabilities = probabilities / total
    selected = int(selected)
    others = np.delete(probabilities, selected)
    runner_up = others.max() if others.size else 0.0
    return float(np.clip(probabilities[selected] - runner_up, 0.0, 1.0))


def confidence_alpha(probabilities, selected, low=DEFAULT_CONFIDENCE_LOW,
                     high=DEFAULT_CONFIDENCE_HIGH, alpha_max=DEFAULT_ALPHA_MAX):
    """The arbitration weight of ``confidence_alpha``:
    `clip((confidence - low) / (high - low), 0, 1) * alpha_max`, with `confidence` the
    margin of the selected goal (`goal_confidence`)."""
    validate_confidence_ramp(low, high, alpha_max)
    confidence = goal_confidence(probabilities, selected)
    return float(np.clip((confidence - low) / (high - low), 0.0, 1.0) * alpha_max)


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
    whether the operator acts this step. `alpha` is the arbitration weight of
    ``fixed_alpha`` and ``confidence_alpha`` (for the latter computed by `confidence_alpha`
    each control period); the other modes ignore it.
    """
    command = validate_command(command)
    reference = played_reference(mode, active, alpha)
    if reference == POLICY:
        return policy_position, policy_velocity
    if reference == SHIFTED:
        return policy_position + command * dt, policy_velocity + command
    operator_position = robot_position + command * dt
    if reference == OPERATOR:
        return operator_position, command
    return ((1.0 - alpha) * operator_position + alpha * policy_position,
            (1.0 - alpha) * command + alpha * policy_velocity)
